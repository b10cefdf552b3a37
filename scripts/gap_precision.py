"""How precise each gap repair acts on is (:class:`ara.eval.coverage.Gaps`): how many
references would read as leaving part of their sentence out (a right answer matches
its reference, so each one is a right answer repair would wrongly try to mend), and,
for a run of ``scripts/eval_generalization.sh``, how many flagged answers were right
and how many wrong.

    .venv/bin/python scripts/gap_precision.py [--run RUN] [--variant C] [--json] [--show N]

Sets: the three hand-written suites, the compositional test side, NL2TL's timed dev file,
the paper split's test side, and the compositional training mixture (whose NL2TL labels
are noisy). Kinds: ``aps`` and ``numbers`` (a listed proposition, a stated bound left
out), ``unasked`` (operators nested or steps ordered unasked), ``order`` (an order asked
for and not written), ``claims`` (what the sentence asks to hold, happen or recur and the
formula never says).
"""

from __future__ import annotations

import argparse
import json
import sys
from collections import Counter
from pathlib import Path

from ara.data import load_or_prepare
from ara.data.handwritten import suite_records
from ara.eval.coverage import KINDS, gaps
from ara.grammars import parse

RESULTS = Path("docs/results/generalization")


def reference_sets() -> dict[str, list]:
    compositional = load_or_prepare("compositional")
    return {"hand-written suite": suite_records("handwritten"),
            "second suite": suite_records("handwritten2"),
            "third suite": suite_records("handwritten3"),
            "compositional test": compositional.records("test"),
            "NL2TL timed dev": load_or_prepare("timed").records("test"),
            "paper split, test side": load_or_prepare("paper").records("test"),
            "training mixture": compositional.records("train")}


def flagged_references(records: list, show: int) -> tuple[Counter, list[str]]:
    counts: Counter = Counter()
    shown = []
    for r in records:
        kinds = gaps(r.nl, r.aps, parse(r.stl)).kinds()
        counts.update(kinds)
        if kinds and len(shown) < show:
            shown.append(f"{'/'.join(kinds)}: {r.nl} -> {r.stl}")
    return counts, shown


def flagged_answers(run: Path, variant: str) -> dict[str, dict[str, Counter]]:
    """Per set of the run, per kind, how many flagged answers were right and wrong."""
    out: dict[str, dict[str, Counter]] = {}
    for samples in sorted([*run.glob("samples.jsonl"), *run.glob("*/samples.jsonl")]):
        per_kind: dict[str, Counter] = {kind: Counter() for kind in KINDS}
        for line in samples.read_text().splitlines():
            row = json.loads(line)
            if row.get("variant") != variant or not row.get("stl"):
                continue
            verdict = "right" if row["equivalent"] else "wrong"
            for kind in gaps(row["nl"], row["aps"], parse(row["stl"])).kinds():
                per_kind[kind][verdict] += 1
        out[samples.parent.name] = per_kind
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--run", help="a run folder (or a folder of runs, such as one "
                        "under docs/results/generalization) whose answers to count, "
                        "right / wrong per kind of gap")
    parser.add_argument("--variant", default="C", help="the run's variant to count (C)")
    parser.add_argument("--show", type=int, default=0, metavar="N",
                        help="print up to N flagged references of each set")
    parser.add_argument("--json", action="store_true", help="print JSON, not Markdown")
    args = parser.parse_args(argv)
    run = None
    if args.run:
        run = Path(args.run) if Path(args.run).is_dir() else RESULTS / args.run
        if not run.is_dir():
            parser.error(f"no run folder {args.run} (nor {RESULTS / args.run})")
    references = {}
    for name, records in reference_sets().items():
        counts, shown = flagged_references(records, args.show)
        references[name] = {"references": len(records), **{k: counts[k] for k in KINDS}}
        for line in shown:
            print(f"  {name}: {line}", file=sys.stderr)
    answers = flagged_answers(run, args.variant) if run else {}
    if args.json:
        print(json.dumps({"references": references,
                          "answers": {s: {k: dict(c) for k, c in per.items()}
                                      for s, per in answers.items()}}, indent=1))
        return 0
    print("References a check flags (each is a right answer repair would act on):\n")
    print("| set | references | " + " | ".join(KINDS) + " |")
    print("|---|---:|" + "---:|" * len(KINDS))
    for name, row in references.items():
        print(f"| {name} | {row['references']:,} | "
              + " | ".join(str(row[k]) for k in KINDS) + " |")
    if answers:
        print(f"\nAnswers of `{args.run}` ({args.variant}) a check flags, right / wrong:\n")
        print("| set | " + " | ".join(KINDS) + " |")
        print("|---|" + "---:|" * len(KINDS))
        for name, per in answers.items():
            print(f"| {name} | " + " | ".join(
                f"{per[k]['right']} / {per[k]['wrong']}" for k in KINDS) + " |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
