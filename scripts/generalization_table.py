"""The generalization table: each model on each evaluation set, from the runs that
``scripts/eval_generalization.sh`` wrote.

    .venv/bin/python scripts/generalization_table.py [--results runs/generalization]
        [--models shipped-greedy,candidate] [--test compositional=2cc898a81b54]
        [--trained-on NAME=SPLIT:VERSION]

Each folder of ``--results`` holding runs is a model (``--models`` picks and orders
them), its column headed by the folder's name.

A cell is accuracy / validity in % over all pairs of the run (invalid and undecided
answers count as wrong). ``unseen`` is the accuracy on the pairs whose sentence does not
occur in that model's own training data: the version a shipped adapter's record in
``eval/models/`` names (found by the adapter's hash in the run's model id), the one
``--trained-on`` gives, else for an adapter the registered compositional mixture and for
any other model nothing (the output says which it assumed), the figure that says what a
user's new sentence can expect; the paper split's lifted test side is almost all seen. A
run whose pairs are not all pairs of the test data (the registered version, or the one
``--test SPLIT=VERSION`` names) is left out and listed: the timed dev file's labels were
corrected in timed version 5f389aa2c4b4, and each version of the compositional mixture
has its own test side (a run on an earlier one lives in ``<set>-<form>@<version>``).
Writes ``summary.json`` beside the runs.
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
from collections import defaultdict
from datetime import date
from pathlib import Path

from ara.data.handwritten import SUITES
from ara.eval.translate.models import SHIPPED

SETS = [*((suite, form) for suite in SUITES for form in ("lifted", "grounded")),
        ("compositional", "lifted"), ("compositional", "grounded"),
        ("timed", "lifted"), ("paper", "lifted"), ("disjoint", "lifted")]
VARIANTS = [("none", 0), ("C", 0), ("F+C", 5)]


def trained_on(folder: Path, given: dict[str, tuple[str, str]], notes: list[str]
               ) -> tuple[str, str] | None:
    """(split, version) the model behind ``folder``'s runs trained on, None for none."""
    if folder.name in given:
        return given[folder.name]
    run = json.loads(next(folder.glob("*/run.json")).read_text())
    if "+lora:sha256:" not in run["model_id"]:
        notes.append(f"{folder.name}: no adapter in its model id; 'unseen' assumes it trained "
                     "on nothing (else pass --trained-on)")
        return None
    digest = run["model_id"].rsplit("+lora:sha256:", 1)[1]
    for record in sorted(SHIPPED.glob("*.json")):
        shipped = json.loads(record.read_text())
        if shipped.get("sha256", "").startswith(digest):
            data = shipped["run"]["data"]
            return data["split"], data["version"]
    from ara.data import registered_version

    version = registered_version("compositional")
    notes.append(f"{folder.name}: an adapter not shipped here; 'unseen' assumes it trained "
                 f"on compositional {version} (else pass --trained-on)")
    return "compositional", version


def training_sentences(trained_on: tuple[str, str] | None, notes: list[str]) -> set[str]:
    if trained_on is None:
        return set()
    from ara.data import load_or_prepare, load_split
    from ara.errors import DataVersionError

    split, version = trained_on
    try:
        data = load_split(split, 0, version=version)
    except DataVersionError:
        data = load_or_prepare(split, 0)
        notes.append(f"{split} {version} is not prepared here: 'unseen' counted against "
                     f"{data.version}")
    return {r.nl for r in data.records("train")}


def cell(samples: list[dict], seen: set[str]) -> dict:
    unseen = [s for s in samples if s["nl"] not in seen]
    return {
        "pairs": len(samples),
        "accuracy": 100 * statistics.fmean(bool(s["equivalent"]) for s in samples),
        "validity": 100 * statistics.fmean(bool(s["valid"]) for s in samples),
        "unseen_pairs": len(unseen),
        "unseen_accuracy": (100 * statistics.fmean(bool(s["equivalent"]) for s in unseen)
                            if unseen else None),
        "median_ms": statistics.median(s["ms"] for s in samples),
    }


def collect(results: Path, models: list[str], test_versions: dict[str, str] | None = None,
            given: dict[str, tuple[str, str]] | None = None
            ) -> tuple[dict, list[str], list[str]]:
    """The table, the runs left out because their test data is not the one chosen
    (``test_versions``: split -> version; the registered one otherwise), and notes."""
    from ara.data import load_or_prepare, load_split

    def test_side(split: str):
        version = (test_versions or {}).get(split)
        data = load_split(split, 0, version=version) if version else load_or_prepare(split, 0)
        return data.version, {(r.nl, r.stl) for r in data.records("test")}

    table: dict = defaultdict(dict)
    stale: list[str] = []
    notes: list[str] = []
    current = {split: test_side(split) for split in {split for split, _ in SETS}}
    for folder in models:
        seen = training_sentences(trained_on(results / folder, given or {}, notes), notes)
        for split, form in SETS:
            version, pairs = current[split]
            # A run on an earlier version of the test data keeps it in its folder name
            found = [results / folder / f"{split}-{form}{suffix}" / "samples.jsonl"
                     for suffix in (f"@{version}", "")]
            path = next((p for p in found if p.exists()), None)
            if path is None:
                continue
            samples = [json.loads(line) for line in path.read_text().splitlines()]
            if any((s["nl"], s["reference"]) not in pairs for s in samples):
                version = json.loads(path.with_name("run.json").read_text())["data"]["version"]
                stale.append(f"{folder}/{split}-{form} (data {version})")
                continue
            by_variant = defaultdict(list)
            for s in samples:
                by_variant[(s["variant"], s["shots"])].append(s)
            for key, samples in by_variant.items():
                table[(split, form, *key)][folder] = cell(samples, seen)
    return table, stale, notes


def markdown(table: dict, models: list[str]) -> str:
    names = [m for m in models if any(m in row for row in table.values())]
    head = "| set | form | variant | pairs | " + " | ".join(names) + " |"
    lines = [head, "|---|---|---|---:|" + "---:|" * len(names)]
    for split, form in SETS:
        for variant, shots in VARIANTS:
            row = table.get((split, form, variant, shots))
            if not row:
                continue
            pairs = next(iter(row.values()))["pairs"]
            cells = []
            for m in names:
                c = row.get(m)
                if c is None:
                    cells.append("-")
                    continue
                text = f"{c['accuracy']:.1f} / {c['validity']:.0f}"
                if c["unseen_pairs"] < c["pairs"] and c["unseen_accuracy"] is not None:
                    text += f" (unseen {c['unseen_accuracy']:.1f}, n={c['unseen_pairs']})"
                cells.append(text)
            label = variant if not shots else f"{variant} {shots}-shot"
            lines.append(f"| {split} | {form} | {label} | {pairs} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--results", type=Path, default=Path("runs/generalization"))
    parser.add_argument("--test", action="append", default=[], metavar="SPLIT=VERSION",
                        help="compare on this prepared version of a split's test side "
                             "(default: the registered one); repeatable")
    parser.add_argument("--models", help="comma-separated folders of --results, in the "
                        "table's order (default: every folder holding runs, sorted)")
    parser.add_argument("--trained-on", action="append", default=[],
                        metavar="NAME=SPLIT:VERSION",
                        help="the data a model trained on, for 'unseen'; repeatable")
    args = parser.parse_args()
    try:
        test_versions = dict(item.split("=", 1) for item in args.test)
        given = {name: tuple(data.split(":", 1)) for name, data in
                 (item.split("=", 1) for item in args.trained_on)}
        if any(len(data) != 2 for data in given.values()):
            raise ValueError
    except ValueError:
        parser.error("--test takes SPLIT=VERSION and --trained-on NAME=SPLIT:VERSION")
    found = sorted(p.parent.parent.name for p in args.results.glob("*/*/samples.jsonl"))
    models = args.models.split(",") if args.models else list(dict.fromkeys(found))
    missing = [m for m in models if m not in found]
    if missing or not models:
        parser.error(f"no runs under {args.results} for {missing or 'any model'}")
    table, stale, notes = collect(args.results, models, test_versions, given)
    print(markdown(table, models))
    print("\nCells: accuracy / validity in %; (unseen ...): accuracy on the pairs whose "
          "sentence is not in that model's training data.")
    if stale:
        print("Left out, made on another version of their test data: " + ", ".join(stale))
    for note in dict.fromkeys(notes):
        print(note)
    summary = {"date": date.today().isoformat(), "machine": platform.platform(),
               "cells": [{"set": k[0], "form": k[1], "variant": k[2], "shots": k[3],
                          "model": m, **c} for k, row in sorted(table.items())
                         for m, c in row.items()],
               "test_versions": test_versions, "left_out": stale, "notes": notes}
    (args.results / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")


if __name__ == "__main__":
    main()
