"""The generalization table: each model on each evaluation set, from the runs that
``scripts/eval_generalization.sh`` wrote.

    .venv/bin/python scripts/generalization_table.py [--results runs/generalization]

    .venv/bin/python scripts/generalization_table.py --test compositional=2cc898a81b54

A cell is accuracy / validity in % over all pairs of the run (invalid and undecided
answers count as wrong). ``unseen`` is the accuracy on the pairs whose sentence does
not occur in that model's own training data (the data version it trained on, where
that version is prepared on this machine; else the current one, and the output says
so), the figure that says what a user's new sentence can expect; the paper split's
lifted test side is almost all seen. A run whose pairs are not all pairs of the test
data (the registered version, or the one ``--test SPLIT=VERSION`` names) is left out
and listed: the timed dev file's labels were corrected in timed version 5f389aa2c4b4,
and each version of the compositional mixture has its own test side (a run on an
earlier one lives in ``<set>-<form>@<version>``). Writes ``summary.json`` beside the
runs.
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

#: Results folder -> (label, (split, data version) the model trained on, or None).
MODELS = {
    "base-270m": ("base", None),
    "paper-adapter-270m": ("paper adapter (old)", ("paper", "1de1d813ead6")),
    "compositional-adapter-v1-270m": ("compositional adapter v1",
                                      ("compositional", "7694e7d55174")),
    "compositional-adapter-v2-270m": ("compositional adapter v2",
                                      ("compositional", "c3c2564014d2")),
    "compositional-adapter-v3-270m": ("compositional adapter v3",
                                      ("compositional", "2cc898a81b54")),
    "compositional-adapter-v4-270m": ("compositional adapter v4",
                                      ("compositional", "2cc898a81b54")),
    "compositional-adapter-v5-270m": ("compositional adapter v5 (not shipped)",
                                      ("compositional", "2cc898a81b54")),
    "compositional-adapter-v6-270m": ("compositional adapter v6 (not shipped)",
                                      ("compositional", "820c2d11c0c8")),
    "compositional-adapter-v7-270m": ("compositional adapter v7 (not shipped)",
                                      ("compositional", "6c3132045205")),
    "compositional-adapter-v8-270m": ("compositional adapter v8 (not shipped)",
                                      ("compositional", "6c3132045205")),
    "compositional-adapter-v9-270m": ("compositional adapter v9 (v7, seed 6; not shipped)",
                                      ("compositional", "6c3132045205")),
    "soup-v4v7v8-270m": ("soup v4+v7+v8 (not shipped)", ("compositional", "6c3132045205")),
    "soup-v7v8v9-270m": ("soup v7+v8+v9 (not shipped)", ("compositional", "6c3132045205")),
    "soup-v7v9-270m": ("soup v7+v9 (not shipped)", ("compositional", "6c3132045205")),
    "compositional-adapter-v10-270m": ("compositional adapter v10 (v7, timed rows x2)",
                                       ("compositional", "6c3132045205")),
    "compositional-adapter-v11-270m": ("compositional adapter v11 (v10 on 3.2.0)",
                                       ("compositional", "690d5d4a1e5f")),
    "compositional-adapter-v12-270m": ("compositional adapter v12 (v11, seed 6)",
                                       ("compositional", "690d5d4a1e5f")),
    "compositional-adapter-v13-270m": ("compositional adapter v13 (v11 on 3.3.0)",
                                       ("compositional", "9c33668eac7c")),
    "compositional-adapter-v14-270m": ("compositional adapter v14 (v13 trained on, on 3.4.0)",
                                       ("compositional", "aaa2649e1656")),
    "soup-v13v14-270m": ("soup v13+v14 (shipped until 2026-11-24)",
                         ("compositional", "aaa2649e1656")),
    "compositional-adapter-v15-270m": ("compositional adapter v15 (soup v13+v14 on 3.5.0)",
                                       ("compositional", "89be643cc979")),
    "soup-v13v14-v15-270m": ("soup (v13+v14)+v15 (shipped until 2026-11-24)",
                             ("compositional", "89be643cc979")),
    "soup-shipped-r32-270m": ("soup (v13+v14)+v15 at rank 32 (SVD)",
                              ("compositional", "89be643cc979")),
    "soup-shipped-r16-270m": ("soup (v13+v14)+v15 at rank 16 (SVD)",
                              ("compositional", "89be643cc979")),
    "compositional-adapter-v16-270m": ("compositional adapter v16 (rank-16 soup on 3.5.0)",
                                       ("compositional", "89be643cc979")),
    "soup-r16v16-270m": ("soup (rank-16 soup)+v16 at rank 16",
                         ("compositional", "89be643cc979")),
    "compositional-adapter-v17-270m": ("compositional adapter v17 (v16 trained on, seed 10)",
                                       ("compositional", "89be643cc979")),
    "compositional-adapter-v18-270m": ("compositional adapter v18 (v16 on 3.6.0)",
                                       ("compositional", "e910409c3f2c")),
    "soup-v16v17-270m": ("soup v16+v17 at rank 16", ("compositional", "89be643cc979")),
    "compositional-adapter-v19-270m": ("compositional adapter v19 (soup v16+v17 on 3.6.0, "
                                       "150 steps, lr 1e-4)", ("compositional", "e910409c3f2c")),
    "compositional-adapter-v20-270m": ("compositional adapter v20 (v19, seed 13)",
                                       ("compositional", "e910409c3f2c")),
    "soup-s-v19-270m": ("soup (v16+v17)+v19 at rank 16", ("compositional", "e910409c3f2c")),
    "soup-s-v19-v20-270m": ("soup (v16+v17)+v19+v20 at rank 16",
                            ("compositional", "e910409c3f2c")),
    "soup-s-v20-270m": ("soup (v16+v17)+v20 at rank 16", ("compositional", "e910409c3f2c")),
    "soup-v16v17-repair8-270m": ("soup v16+v17 (shipped), repair 8 by samples",
                                 ("compositional", "89be643cc979")),
    "soup-v16v17-edits-270m": ("soup v16+v17 (shipped), repair 8 by edits",
                               ("compositional", "89be643cc979")),
    "soup-v16v17-samples-edits-270m": ("soup v16+v17 (shipped), repair 8 by samples+edits",
                                       ("compositional", "89be643cc979")),
    "soup-v16v17-doubt-270m": ("soup v16+v17 (shipped), repair 8 by samples+edits, doubt 0.5",
                               ("compositional", "89be643cc979")),
    "soup-v16v17-fresh-270m": ("soup v16+v17 (shipped), greedy, history-independent "
                               "backend (2026-11-25)", ("compositional", "89be643cc979")),
    "soup-v16v17-doubt-fresh-270m": ("soup v16+v17 (shipped), as ara translate, "
                                     "history-independent backend (2026-11-25)",
                                     ("compositional", "89be643cc979")),
    "soup-v16v17-unasked-270m": ("soup v16+v17 (shipped), as ara translate, repair also "
                                 "on operators nested unasked (2026-11-25)",
                                 ("compositional", "89be643cc979")),
    "soup-v16v17-order-270m": ("soup v16+v17 (shipped), as ara translate, repair also "
                               "on order left out or unasked (2026-11-25)",
                               ("compositional", "89be643cc979")),
    "soup-v16v17-claims-270m": ("soup v16+v17 (shipped), as ara translate, repair also "
                                "on G, F, G(F) asked for in words (2026-11-25)",
                                ("compositional", "89be643cc979")),
    "soup-v16v17-full-270m": ("soup v16+v17 (shipped), every variant, history-independent "
                              "backend (2026-11-25)", ("compositional", "89be643cc979")),
    "soup-v16v18-270m": ("soup v16+v18 at rank 16", ("compositional", "e910409c3f2c")),
    "soup-v11v12v13-270m": ("soup v11+v12+v13 (not shipped)", ("compositional", "9c33668eac7c")),
    "soup-v7v8-270m": ("soup v7+v8 (shipped until 2026-11-23)",
                       ("compositional", "6c3132045205")),
    "soup-v7v8v10-270m": ("soup v7+v8+v10 (shipped until 2026-11-24)",
                          ("compositional", "6c3132045205")),
    "soup-v11v12-270m": ("soup v11+v12 (shipped until 2026-11-24)",
                         ("compositional", "690d5d4a1e5f")),
    "v16-shipped-270m": ("v16 (shipped until 2026-11-24)", ("compositional", "89be643cc979")),
    "shipped-greedy": ("soup v16+v17 and its 3.7 warm start (shipped 2026-11-26)",
                       ("compositional", "f7eb90893a26")),
    "shipped-repair8": ("the same, as ara translate (2026-11-26)",
                        ("compositional", "f7eb90893a26")),
    "compositional-adapter-270m": ("soup v16+v17 (shipped until 2026-11-26)",
                                   ("compositional", "89be643cc979")),
}
SETS = [*((suite, form) for suite in SUITES for form in ("lifted", "grounded")),
        ("compositional", "lifted"), ("compositional", "grounded"),
        ("timed", "lifted"), ("paper", "lifted"), ("disjoint", "lifted")]
VARIANTS = [("none", 0), ("C", 0), ("F+C", 5)]


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


def collect(results: Path, test_versions: dict[str, str] | None = None
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
    for folder, (_, trained_on) in MODELS.items():
        seen = training_sentences(trained_on, notes)
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


def markdown(table: dict) -> str:
    names = [m for m in MODELS if any(m in row for row in table.values())]
    head = "| set | form | variant | pairs | " + " | ".join(MODELS[m][0] for m in names) + " |"
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
    args = parser.parse_args()
    try:
        test_versions = dict(item.split("=", 1) for item in args.test)
    except ValueError:
        parser.error(f"--test takes SPLIT=VERSION, got {args.test}")
    table, stale, notes = collect(args.results, test_versions)
    print(markdown(table))
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
