"""How long a user waits for `ara translate`'s answer, with and without the time budget,
side by side in one run on the same held-out sentences.

    .venv/bin/python bench/answer_budget.py [--split timed] [--limit 100] [--budget 5]
        [--model finetuned] [--out runs/bench/answer-budget.json]

Each sentence (``--limit`` of the split's test side, drawn with seed 0; the default is
NL2TL's timed dev set, where long bounds over many propositions make the slowest
answers) is answered as ``ara translate`` answers it (:func:`~ara.eval.translate.answering.answer`:
repair, confidence, the other readings, the gap checks), once within ``--budget``
seconds and once unbounded (``--budget 0``), the budgeted one first so that the Spot
results and prompts it leaves cached can only speed up the unbounded one. The time is
the answer's ``ms``, the whole wait. The table gives p50/p90/max per row, how many
answers took longer than the budget (greedy decoding is never cut, so a budgeted answer
can), how many ran out of time (their search was cut short), and how many differ from
the unbounded answer.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import random
from datetime import date
from pathlib import Path

from tqdm import tqdm

from ara import __version__
from ara.data import load_or_prepare
from ara.eval.translate.answering import BUDGET_S, AnswerConfig, answer, worked_examples
from ara.eval.translate.models import make_backend
from ara.eval.translate.translator import Translator
from ara.provenance import git_commit


def percentile(values: list[float], q: float) -> float:
    """The nearest-rank ``q`` quantile (0 < q <= 1) of ``values``."""
    ranked = sorted(values)
    return ranked[max(0, math.ceil(q * len(ranked)) - 1)]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--split", default="timed", help="a held-out split; its test side")
    ap.add_argument("--limit", type=int, default=100, help="sentences (default 100)")
    ap.add_argument("--budget", type=float, default=BUDGET_S, help="seconds per answer")
    ap.add_argument("--model", default="finetuned")
    ap.add_argument("--out", type=Path, default=Path("runs/bench/answer-budget.json"))
    args = ap.parse_args()
    records = load_or_prepare(args.split).records("test")
    if args.limit < len(records):
        records = random.Random(0).sample(records, args.limit)
    translator = Translator(make_backend(args.model))
    translator.translate(records[0].nl, records[0].aps)  # warm: load, compile the grammar
    configs = {f"--budget {args.budget:g}": AnswerConfig(budget_s=args.budget),
               "unbounded (--budget 0)": AnswerConfig(budget_s=0)}
    rows = []
    for r in tqdm(records, unit="sentence"):
        shots = worked_examples(args.model, None, r.aps, nl=r.nl)
        row = {"uid": r.uid, "nl": r.nl, "aps": list(r.aps)}
        for label, config in configs.items():
            a = answer(translator, r.nl, r.aps, shots, config)
            row[label] = {"stl": a.stl, "ms": round(a.ms, 1), "ran_out": a.ran_out,
                          "attempts": a.attempts}
        rows.append(row)
    budgeted, unbounded = configs
    print(f"# {len(rows)} sentences of {args.split} (test side), {translator.backend.model_id}, "
          f"as `ara translate` answers; {platform.machine()}, {os.cpu_count()} cores")
    print(f"| answer | p50 ms | p90 ms | max ms | over {args.budget:g} s | ran out | "
          "differs from unbounded |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    summary = {}
    for label in configs:
        ms = [row[label]["ms"] for row in rows]
        summary[label] = {
            "p50_ms": percentile(ms, 0.5), "p90_ms": percentile(ms, 0.9), "max_ms": max(ms),
            "over_budget": sum(x > args.budget * 1e3 for x in ms),
            "ran_out": sum(row[label]["ran_out"] for row in rows),
            "differs": sum(row[label]["stl"] != row[unbounded]["stl"] for row in rows)}
        s = summary[label]
        print(f"| {label} | {s['p50_ms']:.0f} | {s['p90_ms']:.0f} | {s['max_ms']:.0f} | "
              f"{s['over_budget']} | {s['ran_out']} | {s['differs']} of {len(rows)} |")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps({
        "date": date.today().isoformat(), "ara_version": __version__,
        "git_commit": git_commit(), "machine": platform.platform(), "cpus": os.cpu_count(),
        "model": translator.backend.model_id, "split": args.split, "limit": args.limit,
        "budget_s": args.budget, "summary": summary, "rows": rows}, indent=2) + "\n")
    print(f"\nrows in {args.out}")


if __name__ == "__main__":
    main()
