"""Which extra answers fix a translation that leaves part of the request out?

Takes the answers a repaired evaluation run had to repair (``attempts > 1`` in its
samples.jsonl: the greedy answer had a gap of :data:`ara.eval.translate.checks.KINDS`, or the
model doubted it), or
the test pairs of a split whose greedy answer has such a gap (``--split``: the first
``--limit`` of its test side shuffled with seed 0, less the sentences of the runs
``--exclude`` names, so that answers already read are left out), translates each
again, and judges with Spot, side by side:

- ``greedy``: the greedy answer alone;
- ``samples``: K samples under the request's grammar, majority of the answers that
  leave out least (``--repair-by samples``; :func:`ara.eval.translate.repair.translate_repaired`);
- ``forced``: one greedy answer under a grammar that must write what was left out
  (:func:`ara.grammars.require_literals`);
- ``forced+samples``: both kinds of extra answer, ranked as the shipped repair ranks;
- ``forced samples``: K samples under the forcing grammar, majority;
- ``edits``: the formulas one edit from the greedy answer that write what it left out
  (:func:`ara.eval.translate.repair.literal_mends`), the one the model scores highest
  (``--repair-by edits``);
- ``samples+edits``: the K samples and those edits, the highest-scoring of the answers
  that leave out least (``--repair-by samples+edits``, the default).

    .venv/bin/python bench/repair_strategies.py \\
        (--runs 'runs/generalization/soup-v16v17-repair8-270m/*'
         | --split compositional --form lifted --limit 200 --exclude 'RUN_DIRS/*') \\
        [--model finetuned] [--samples 8] [--spot-timeout 10]
        [--strategies greedy,samples,edits] [--out runs/bench/repair-strategies.json]
"""

from __future__ import annotations

import argparse
import glob
import json
import os
import platform
import random
from datetime import date
from pathlib import Path

from tqdm import tqdm

from ara.data import load_or_prepare
from ara.eval.translate.backends.base import Sampling
from ara.eval.translate.checks import gaps
from ara.eval.translate.models import make_backend
from ara.eval.translate.repair import (
    _missing,
    literal_mends,
    rank_repairs,
    rank_scored,
    score_complete,
)
from ara.eval.translate.request import Request
from ara.eval.translate.translator import Translator
from ara.grammars import parse
from ara.grammars.spot_bridge import judge

STRATEGIES = ("greedy", "samples", "forced", "forced+samples", "forced samples", "edits",
              "samples+edits")
SCORED = ("edits", "samples+edits")


def repaired_rows(pattern: str) -> list[dict]:
    """The samples that the run behind each folder matching ``pattern`` repaired."""
    rows = []
    for path in sorted(glob.glob(str(Path(pattern) / "samples.jsonl"))):
        rows += [r for r in map(json.loads, Path(path).read_text().splitlines())
                 if r.get("attempts", 1) > 1]
    return rows


def gapped_rows(translator: Translator, split: str, form: str, limit: int,
                exclude: str | None) -> list[dict]:
    """The test pairs of ``split`` whose greedy answer leaves part of the request out."""
    seen = set()
    for path in glob.glob(str(Path(exclude) / "samples.jsonl")) if exclude else ():
        seen |= {json.loads(line)["nl"] for line in Path(path).read_text().splitlines()}
    records = [r for r in load_or_prepare(split).records("test", form) if r.nl not in seen]
    records = random.Random(0).sample(records, len(records))[:limit]
    rows = []
    for r in tqdm(records, desc="greedy answers", unit="pair"):
        greedy = translator.translate(r.nl, r.aps).stl
        if 0 < _missing(Request.of(r.nl, r.aps), greedy) < float("inf"):
            rows.append({"nl": r.nl, "aps": list(r.aps), "reference": r.stl})
    return rows


def candidates(translator: Translator, nl: str, aps: list[str], k: int,
               strategies: tuple[str, ...]) -> dict[str, list]:
    """Each strategy's answers, greedy first."""
    greedy = translator.translate(nl, aps).stl
    request = Request.of(nl, aps)
    gap = gaps(request, parse(greedy))
    missing = (*gap.aps, *map(str, gap.numbers))
    draws = [translator.translate(nl, aps, sampling=Sampling(0.7, seed=i)).stl
             for i in range(1, k + 1)]
    out = {"greedy": [greedy], "samples": [greedy, *draws]}
    if {"forced", "forced+samples", "forced samples"} & set(strategies):
        forced = translator.translate(nl, aps, require=missing).stl
        forced_draws = [translator.translate(nl, aps, sampling=Sampling(0.7, seed=i),
                                             require=missing).stl for i in range(1, k + 1)]
        out |= {"forced": [greedy, forced], "forced+samples": [greedy, forced, *draws],
                "forced samples": [greedy, *forced_draws]}
    edits = literal_mends(translator, request, greedy)
    return out | {"edits": [greedy, *edits], "samples+edits": [greedy, *draws, *edits]}


def winner(translator: Translator, nl: str, aps: list[str], answers: list, scored: bool,
           timeout_s: float) -> str | None:
    missing = [_missing(Request.of(nl, aps), a) for a in answers]
    if not scored:
        return answers[rank_repairs(answers, missing, timeout_s)[0][0]]
    scores = score_complete(translator, nl, aps, answers, missing)
    return answers[rank_scored(missing, scores)[0]]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("--runs", help="Glob of evaluation folders (each with samples.jsonl).")
    source.add_argument("--split", help="A prepared split whose test pairs to translate.")
    parser.add_argument("--form", default="lifted", help="With --split: lifted or grounded.")
    parser.add_argument("--limit", type=int, default=200, help="With --split: pairs to try.")
    parser.add_argument("--exclude", help="With --split: glob of evaluation folders whose "
                                          "sentences to leave out.")
    parser.add_argument("--model", default="finetuned")
    parser.add_argument("--samples", type=int, default=8, help="K extra answers to draw.")
    parser.add_argument("--spot-timeout", type=float, default=10.0,
                        help="Seconds per Spot check between answers (an undecided pair "
                             "counts as different) and against the reference.")
    parser.add_argument("--strategies", default=",".join(STRATEGIES),
                        help=f"Comma-separated, of {', '.join(STRATEGIES)}.")
    parser.add_argument("--out", type=Path, default=Path("runs/bench/repair-strategies.json"))
    args = parser.parse_args()
    strategies = tuple(args.strategies.split(","))
    if unknown := set(strategies) - set(STRATEGIES):
        parser.error(f"unknown strategies {sorted(unknown)}; choose of {', '.join(STRATEGIES)}")
    translator = Translator(make_backend(args.model))
    if args.runs:
        rows = repaired_rows(args.runs)
        if not rows:
            parser.error(f"no repaired answers under {args.runs!r}: pass folders of a run "
                         "made with --repair")
        source = f"--runs {args.runs}"
    else:
        rows = gapped_rows(translator, args.split, args.form, args.limit, args.exclude)
        source = (f"--split {args.split} --form {args.form} --limit {args.limit}"
                  + (f" --exclude '{args.exclude}'" if args.exclude else ""))
    records = []
    for row in tqdm(rows, desc="repaired answers", unit="answer"):
        nl, aps, ref = row["nl"], row["aps"], row["reference"]
        answers = candidates(translator, nl, aps, args.samples, strategies)
        chosen = {name: winner(translator, nl, aps, answers[name], name in SCORED,
                               args.spot_timeout) for name in strategies}
        records.append({"nl": nl, "aps": aps, "reference": ref, "chosen": chosen,
                        "right": {name: bool(judge(ref, stl, args.spot_timeout)["equivalent"])
                                  for name, stl in chosen.items()}})
    right = {name: sum(r["right"][name] for r in records) for name in strategies}
    print(f"{'strategy':16s} right of {len(records)}")
    for name in strategies:
        print(f"{name:16s} {right[name]:>3d}")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps({
        "command": f"bench/repair_strategies.py {source}"
                   + f" --model {args.model} --samples {args.samples}"
                   + f" --spot-timeout {args.spot_timeout:g} --strategies {args.strategies}",
        "date": date.today().isoformat(),
        "machine": f"{platform.platform()}, {os.cpu_count()} cores",
        "answers": len(records), "right": right, "records": records}, indent=1) + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
