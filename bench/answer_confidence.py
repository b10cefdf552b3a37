"""How well the model's probability of its own answer tells right answers from wrong.

    .venv/bin/python bench/answer_confidence.py \
        --runs 'runs/generalization/soup-v16v17-270m/*' --dev 'compositional-*' \
        [--model finetuned] [--out runs/bench/answer-confidence.json]
    .venv/bin/python bench/answer_confidence.py \
        --runs 'runs/generalization/soup-v16v17-270m/[ht]*' --resample 8 \
        --out runs/bench/answer-confidence-resampled.json
    .venv/bin/python bench/answer_confidence.py \
        --runs 'runs/generalization/soup-v16v17-270m/[ht]*' --readings 3 \
        --out runs/bench/answer-confidence-readings.json

Scores every zero-shot constrained (C) answer in the run folders with ``--model`` (the
model that gave them: the bench refuses folders run with another), judged right or
wrong as the run judged it. Prints, per folder, the area under the ROC curve (the chance
that a right answer scores above a wrong one), then, for thresholds on the probability,
how many answers fall below, how many of those are wrong, and how right the rest are,
on the ``--dev`` folders (where :data:`~ara.eval.translate.confidence.DOUBT` was chosen) and on
the others apart. For each wrong answer it also scores the reference: how often the
model would rank the right answer first if it were offered. ``--resample K`` asks
whether flagged answers can be fixed without a reference: each answer below DOUBT is
translated again with self-consistency (greedy + K samples, the largest group by
meaning wins; :func:`~ara.eval.translate.repair.translate_consistent`) and judged; Spot
takes minutes to group the samples of a long compositional formula, hence the second
command's narrower glob (the hand-written suites and the timed set). ``--readings K``
asks what a user who is shown the other readings gains: each answer below DOUBT is
translated again as ``ara translate`` does by default (repair by samples and edits,
:func:`~ara.eval.translate.repair.translate_repaired`), and the winner and up to K other
readings it weighed (:func:`~ara.eval.translate.repair.readings`, what ``ara translate
--alternatives`` lists) are judged: how often the right one is first, among the first
two, and so on.
"""

from __future__ import annotations

import argparse
import fnmatch
import glob
import json
import math
import os
import platform
from datetime import date
from pathlib import Path

from tqdm import tqdm

from ara.eval.translate.confidence import DOUBT, answer_probability
from ara.eval.translate.models import make_backend
from ara.eval.translate.repair import readings, translate_consistent, translate_repaired
from ara.eval.translate.translator import Translator
from ara.grammars.spot_bridge import judge

THRESHOLDS = (0.8, 0.6, DOUBT, 0.3, 0.1)


def auroc(right: list[float], wrong: list[float]) -> float | None:
    """The chance that a right answer's probability is above a wrong one's (ties half)."""
    if not right or not wrong:
        return None
    wins = sum((r > w) + 0.5 * (r == w) for r in right for w in wrong)
    return wins / (len(right) * len(wrong))


def flag_table(records: list[dict]) -> list[dict]:
    """For each threshold: answers below it, the wrong among them, and the accuracy of
    the answers at or above it."""
    rows = []
    for t in THRESHOLDS:
        low = [r for r in records if r["probability"] < t]
        high = [r for r in records if r["probability"] >= t]
        rows.append({"below": t, "flagged": len(low),
                     "wrong_flagged": sum(not r["right"] for r in low),
                     "wrong": sum(not r["right"] for r in records),
                     "right_unflagged": sum(r["right"] for r in high), "unflagged": len(high)})
    return rows


def readings_table(records: list[dict], others: int) -> dict:
    """How many of the flagged answers have the right reading first, among the first
    two, ..., among the first ``1 + others`` (``right_within[k - 1]``)."""
    return {"flagged": len(records),
            "right_within": [sum(any(x["right"] for x in r["readings"][:k]) for r in records)
                             for k in range(1, 2 + others)],
            "shown": [sum(len(r["readings"]) >= k for r in records)
                      for k in range(1, 2 + others)]}


def print_table(name: str, records: list[dict]) -> None:
    n = len(records)
    print(f"\n{name}: {n} answers, {sum(r['right'] for r in records)} right")
    print("| p below | flagged | wrong among flagged | wrong caught | right among the rest |")
    print("|---:|---:|---:|---:|---:|")
    for row in flag_table(records):
        flagged, rest = row["flagged"], row["unflagged"]
        print(f"| {row['below']:g} | {flagged} ({100 * flagged / n:.1f}%) | "
              f"{row['wrong_flagged']} ({100 * row['wrong_flagged'] / max(1, flagged):.0f}%) | "
              f"{row['wrong_flagged']} of {row['wrong']} | {row['right_unflagged']} of {rest} "
              f"({100 * row['right_unflagged'] / max(1, rest):.1f}%) |")


def score_folder(translator: Translator, folder: Path, timeout_s: float,
                 resample: int, others: int) -> list[dict]:
    records = []
    rows = [json.loads(line) for line in (folder / "samples.jsonl").read_text().splitlines()]
    for r in tqdm([r for r in rows if r["variant"] == "C" and r["stl"]], desc=folder.name,
                  unit="answer"):
        record = {"set": folder.name, "nl": r["nl"], "aps": r["aps"],
                  "reference": r["reference"], "stl": r["stl"], "right": bool(r["equivalent"]),
                  "probability": answer_probability(translator, r["nl"], r["aps"], r["stl"])}
        if not record["right"]:
            record["reference_probability"] = answer_probability(translator, r["nl"], r["aps"],
                                                                 r["reference"])
        if resample and record["probability"] < DOUBT:
            vote = translate_consistent(translator, r["nl"], r["aps"], samples=resample + 1,
                                        timeout_s=timeout_s)
            record["resampled"] = {"stl": vote.result.stl, "right": bool(
                judge(r["reference"], vote.result.stl, timeout_s)["equivalent"])}
        if others and record["probability"] < DOUBT:
            vote = translate_repaired(translator, r["nl"], r["aps"], timeout_s=timeout_s)
            record["readings"] = [
                {"stl": stl, "probability": math.exp(score),
                 "right": bool(judge(r["reference"], stl, timeout_s)["equivalent"])}
                for stl, score in readings(vote, timeout_s, limit=1 + others)]
        records.append(record)
    return records


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", required=True,
                        help="Glob of evaluation folders (each with samples.jsonl, run.json).")
    parser.add_argument("--dev", default="compositional-*",
                        help="Glob of folder names the threshold was chosen on.")
    parser.add_argument("--model", default="finetuned",
                        help="The model that gave the answers (any --model value).")
    parser.add_argument("--resample", type=int, default=0,
                        help="Translate flagged answers again with greedy + K samples.")
    parser.add_argument("--readings", type=int, default=0,
                        help="Translate flagged answers again with repair (ara translate's "
                             "default) and judge the winner and up to K other readings.")
    parser.add_argument("--spot-timeout", type=float, default=5.0)
    parser.add_argument("--out", type=Path, default=Path("runs/bench/answer-confidence.json"))
    args = parser.parse_args()
    folders = sorted(Path(p) for p in glob.glob(args.runs) if Path(p, "samples.jsonl").is_file())
    if not folders:
        parser.error(f"no run folders with samples.jsonl under {args.runs!r}")
    translator = Translator(make_backend(args.model))
    for folder in folders:
        ran = json.loads((folder / "run.json").read_text())["model_id"]
        if ran != translator.backend.model_id:
            parser.error(f"{folder} was run with {ran}, not --model {args.model} "
                         f"({translator.backend.model_id}): pass the model that gave the answers")
    records = [rec for folder in folders
               for rec in score_folder(translator, folder, args.spot_timeout, args.resample,
                                       args.readings)]
    areas = {}
    for name in sorted({r["set"] for r in records}) + ["all"]:
        chosen = [r for r in records if name in ("all", r["set"])]
        areas[name] = auroc([r["probability"] for r in chosen if r["right"]],
                            [r["probability"] for r in chosen if not r["right"]])
        print(f"AUROC {name:24s} {len(chosen):4d} answers  {areas[name]:.3f}")
    dev = [r for r in records if fnmatch.fnmatch(r["set"], args.dev)]
    held = [r for r in records if not fnmatch.fnmatch(r["set"], args.dev)]
    for name, chosen in (("dev (" + args.dev + ")", dev), ("the other folders", held)):
        if chosen:
            print_table(name, chosen)
    wrong = [r for r in records if not r["right"]]
    above = sum(r["reference_probability"] > r["probability"] for r in wrong)
    print(f"\nthe model scores the reference above its own wrong answer in {above} of "
          f"{len(wrong)}")
    summary = {"auroc": areas, "dev": flag_table(dev), "held_out": flag_table(held),
               "reference_above_wrong": [above, len(wrong)]}
    if args.resample:
        redone = [r for r in records if "resampled" in r]
        summary["resampled"] = {"flagged": len(redone),
                                "greedy_right": sum(r["right"] for r in redone),
                                "resampled_right": sum(r["resampled"]["right"] for r in redone)}
        print(f"flagged answers translated again with {args.resample} samples: "
              f"{summary['resampled']['resampled_right']} right of {len(redone)} "
              f"(greedy {summary['resampled']['greedy_right']})")
    if args.readings:
        for name, chosen in (("dev (" + args.dev + ")", dev), ("the other folders", held)):
            summary.setdefault("readings", {})[name] = found = readings_table(
                [r for r in chosen if "readings" in r], args.readings)
            print(f"\n{name}: flagged answers translated again, right among the first k "
                  f"readings: {found}")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps({
        "command": f"bench/answer_confidence.py --runs '{args.runs}' --dev '{args.dev}' "
                   f"--model {args.model} --resample {args.resample} --readings {args.readings} "
                   f"--spot-timeout {args.spot_timeout:g}",
        "date": date.today().isoformat(),
        "machine": f"{platform.platform()}, {os.cpu_count()} cores",
        "model_id": translator.backend.model_id, "doubt": DOUBT, **summary,
        "records": records}, indent=1) + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
