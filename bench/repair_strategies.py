"""Which extra answers fix a translation that leaves part of the request out?

Takes the answers a repaired evaluation run had to repair (``attempts > 1`` in its
samples.jsonl: the greedy answer left out a listed proposition or a stated bound),
translates each again, and judges with Spot, side by side:

- ``greedy``: the greedy answer alone;
- ``samples``: the shipped repair, K samples under the request's grammar, majority of
  the answers that leave out least (:func:`ara.eval.consistency.translate_repaired`);
- ``forced``: one greedy answer under a grammar that must write what was left out
  (:func:`ara.grammars.require_literals`);
- ``forced+samples``: both kinds of extra answer, ranked as the shipped repair ranks;
- ``forced samples``: K samples under the forcing grammar, majority.

    .venv/bin/python bench/repair_strategies.py \\
        --runs 'docs/results/generalization/soup-v16v17-repair8-270m/*' \\
        [--model finetuned] [--samples 8] [--spot-timeout 10]
        [--out docs/results/repair-strategies.json]
"""

from __future__ import annotations

import argparse
import glob
import json
import os
import platform
from datetime import date
from pathlib import Path

from tqdm import tqdm

from ara.eval.backends.base import Sampling
from ara.eval.consistency import _missing, rank_repairs
from ara.eval.coverage import gaps
from ara.eval.harness import judge
from ara.eval.models import make_backend
from ara.eval.translator import Translator
from ara.grammars import parse

STRATEGIES = ("greedy", "samples", "forced", "forced+samples", "forced samples")


def repaired_rows(pattern: str) -> list[dict]:
    """The samples that the run behind each folder matching ``pattern`` repaired."""
    rows = []
    for path in sorted(glob.glob(str(Path(pattern) / "samples.jsonl"))):
        rows += [r for r in map(json.loads, Path(path).read_text().splitlines())
                 if r.get("attempts", 1) > 1]
    return rows


def candidates(translator: Translator, nl: str, aps: list[str], k: int) -> dict[str, list]:
    """Each strategy's answers, greedy first."""
    greedy = translator.translate(nl, aps).stl
    gap = gaps(nl, aps, parse(greedy))
    missing = (*gap.aps, *map(str, gap.numbers))
    draws = [translator.translate(nl, aps, sampling=Sampling(0.7, seed=i)).stl
             for i in range(1, k + 1)]
    forced = translator.translate(nl, aps, require=missing).stl
    forced_draws = [translator.translate(nl, aps, sampling=Sampling(0.7, seed=i),
                                         require=missing).stl for i in range(1, k + 1)]
    return {"greedy": [greedy], "samples": [greedy, *draws], "forced": [greedy, forced],
            "forced+samples": [greedy, forced, *draws],
            "forced samples": [greedy, *forced_draws]}


def winner(nl: str, aps: list[str], answers: list, timeout_s: float) -> str | None:
    missing = [_missing(nl, aps, a) for a in answers]
    return answers[rank_repairs(answers, missing, timeout_s)[0][0]]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", required=True,
                        help="Glob of evaluation folders (each with samples.jsonl).")
    parser.add_argument("--model", default="finetuned")
    parser.add_argument("--samples", type=int, default=8, help="K extra answers to draw.")
    parser.add_argument("--spot-timeout", type=float, default=10.0,
                        help="Seconds per Spot check between answers (an undecided pair "
                             "counts as different) and against the reference.")
    parser.add_argument("--out", type=Path, default=Path("docs/results/repair-strategies.json"))
    args = parser.parse_args()
    rows = repaired_rows(args.runs)
    if not rows:
        parser.error(f"no repaired answers under {args.runs!r}: pass folders of a run "
                     "made with --repair")
    translator = Translator(make_backend(args.model))
    records = []
    for row in tqdm(rows, desc="repaired answers", unit="answer"):
        nl, aps, ref = row["nl"], row["aps"], row["reference"]
        answers = candidates(translator, nl, aps, args.samples)
        chosen = {name: winner(nl, aps, answers[name], args.spot_timeout)
                  for name in STRATEGIES}
        records.append({"nl": nl, "aps": aps, "reference": ref, "chosen": chosen,
                        "right": {name: bool(judge(ref, stl, args.spot_timeout)["equivalent"])
                                  for name, stl in chosen.items()}})
    right = {name: sum(r["right"][name] for r in records) for name in STRATEGIES}
    print(f"{'strategy':16s} right of {len(records)}")
    for name in STRATEGIES:
        print(f"{name:16s} {right[name]:>3d}")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps({
        "command": "bench/repair_strategies.py --runs " + args.runs
                   + f" --model {args.model} --samples {args.samples}"
                   + f" --spot-timeout {args.spot_timeout:g}",
        "date": date.today().isoformat(),
        "machine": f"{platform.platform()}, {os.cpu_count()} cores",
        "answers": len(records), "right": right, "records": records}, indent=1) + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
