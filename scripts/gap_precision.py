"""How precise each gap repair acts on is (:func:`ara.eval.metrics.gap_precision`): how
many references would read as leaving part of their sentence out (a right answer
matches its reference, so each one is a right answer repair would wrongly try to mend),
and, for a run of ``scripts/eval_generalization.sh``, how many flagged answers were
right and how many wrong.

    .venv/bin/python scripts/gap_precision.py [--run RUN] [--variant C] [--json] [--show N]

Sets: the first four hand-written suites and the sixth (not the fifth, nor those from the
seventh on: blind judges, past or waiting), the compositional test side, NL2TL's timed dev
file, the paper split's test side, and the compositional training mixture (whose NL2TL
labels are noisy). Kinds: :data:`ara.eval.translate.checks.KINDS`. A reference's first
implication written as its contrapositive (``!b -> !a`` for ``a -> b``) is the same
formula, so a check that flags it would flag a right answer worded that way: the column
"contrapositive" counts those.
"""

from __future__ import annotations

import argparse
import json
import sys
from itertools import islice
from pathlib import Path

from ara.data import load_or_prepare
from ara.data.handwritten import suite_records
from ara.eval.metrics import gap_precision
from ara.eval.translate.checks import KINDS, gaps
from ara.eval.translate.request import Request
from ara.grammars import Formula, Implies, Not, parse
from ara.grammars.ast import children, with_children

RESULTS = Path("docs/results/generalization")


def reference_sets() -> dict[str, list]:
    compositional = load_or_prepare("compositional")
    return {"hand-written suite": suite_records("handwritten"),
            "second suite": suite_records("handwritten2"),
            "third suite": suite_records("handwritten3"),
            # Suites 4 and 6 since their misses were read; 5 and 7 to 9 judge(d) blind.
            "fourth suite": suite_records("handwritten4"),
            "sixth suite": suite_records("handwritten6"),
            "compositional test": compositional.records("test"),
            "NL2TL timed dev": load_or_prepare("timed").records("test"),
            "paper split, test side": load_or_prepare("paper").records("test"),
            "training mixture": compositional.records("train")}


def contrapositive(formula: Formula) -> Formula | None:
    """``formula`` with its first implication ``a -> b`` written ``!b -> !a``, or ``None``."""
    if isinstance(formula, Implies):
        return Implies(_negated(formula.rhs), _negated(formula.lhs))
    kids = children(formula)
    for i, kid in enumerate(kids):
        if (new := contrapositive(kid)) is not None:
            return with_children(formula, (*kids[:i], new, *kids[i + 1:]))
    return None


def _negated(formula: Formula) -> Formula:
    return formula.arg if isinstance(formula, Not) else Not(formula)


def run_answers(run: Path, variant: str) -> dict[str, list[dict]]:
    """Per set of the run (a folder of ``samples.jsonl``), the answers of ``variant``."""
    return {samples.parent.name: [row for row in map(json.loads, samples.read_text().splitlines())
                                  if row.get("variant") == variant]
            for samples in sorted([*run.glob("samples.jsonl"), *run.glob("*/samples.jsonl")])}


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
        counts = gap_precision(records)
        rewritten = [(r, contrapositive(parse(r.stl))) for r in records]
        references[name] = {"references": len(records),
                            **{k: counts[k]["references"] for k in KINDS},
                            "contrapositive": sum(
                                1 for r, c in rewritten if c is not None
                                and gaps(Request.of(r.nl, r.aps), c)
                                and not gaps(Request.of(r.nl, r.aps), parse(r.stl)))}
        flagged = ((r, gaps(Request.of(r.nl, r.aps), parse(r.stl)).kinds()) for r in records)
        for r, kinds in islice(((r, k) for r, k in flagged if k), args.show):
            print(f"  {name}: {'/'.join(kinds)}: {r.nl} -> {r.stl}", file=sys.stderr)
    answers = {name: gap_precision(answers=rows)
               for name, rows in (run_answers(run, args.variant) if run else {}).items()}
    if args.json:
        print(json.dumps({"references": references,
                          "answers": {s: {k: dict(c)
                                          for k, c in per.items()}
                                      for s, per in answers.items()}}, indent=1))
        return 0
    print("References a check flags (each is a right answer repair would act on):\n")
    print("| set | references | " + " | ".join(KINDS) + " | contrapositive |")
    print("|---|---:|" + "---:|" * (len(KINDS) + 1))
    for name, row in references.items():
        print(f"| {name} | {row['references']:,} | "
              + " | ".join(str(row[k]) for k in (*KINDS, "contrapositive")) + " |")
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
