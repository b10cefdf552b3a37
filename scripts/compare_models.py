"""Base vs fine-tuned Gemma 3 270M, from the samples of the README's evaluation runs.

    mkdir -p runs/paper-record
    git archive f4bf9e7 docs/results | tar -x --strip-components=2 -C runs/paper-record
    .venv/bin/python scripts/compare_models.py --results runs/paper-record

For each split, variant and shot count: accuracy and validity over *all* test pairs (an
invalid or undecided answer counts as wrong), averaged over reruns. It reads the run
folders (with their answers) of docs/paper-adapter.md's table, which commit f4bf9e7
holds: the base model's 5-shot and zero-shot runs, the paper-split adapter's, and the
first adapter's (480 steps, zero-shot prompts only). Runs of your own under the same
names (`ara eval ablation --out runs/base-270m-paper ...`) read the same.
"""

from __future__ import annotations

import argparse
import json
import statistics
from collections import defaultdict
from pathlib import Path

RUNS = {"base": ["base-270m-{split}", "base-270m-{split}-zeroshot"],
        "fine-tuned, 0-shot training": ["finetuned-270m-zeroshot480-{split}"],
        "fine-tuned, mixed-shot training": ["finetuned-270m-{split}"]}
ORDER = ["none", "C", "F", "F+P", "F+P+C"]


def cells(folder: Path) -> dict[tuple[str, int], dict]:
    """(variant, shots) -> validity and accuracy in %, mean over reruns, and pairs."""
    per = defaultdict(lambda: defaultdict(list))
    for line in (folder / "samples.jsonl").read_text().splitlines():
        s = json.loads(line)
        per[(s["variant"], s["shots"])][s["rerun"]].append(s)
    out = {}
    for key, reruns in per.items():
        val = [100 * statistics.fmean(x["valid"] for x in r) for r in reruns.values()]
        acc = [100 * statistics.fmean(bool(x["equivalent"]) for x in r) for r in reruns.values()]
        out[key] = {"validity": statistics.fmean(val), "accuracy": statistics.fmean(acc),
                    "reruns": len(reruns), "pairs": len(next(iter(reruns.values())))}
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--results", type=Path, default=Path("runs"))
    args = parser.parse_args()
    print("| split | variant | shots | " + " | ".join(RUNS) + " |")
    print("|---|---|---:|" + "---:|" * len(RUNS))
    for split in ("paper", "disjoint"):
        found = {}
        for model, patterns in RUNS.items():
            found[model] = {}
            for pattern in patterns:
                folder = args.results / pattern.format(split=split)
                if (folder / "samples.jsonl").exists():
                    found[model].update(cells(folder))
        keys = sorted({k for m in found.values() for k in m if k[1] in (0, 5)},
                      key=lambda k: (ORDER.index(k[0]) if k[0] in ORDER else 99, k[1]))
        for key in keys:
            row = [split, key[0], str(key[1])]
            for model in RUNS:
                c = found[model].get(key)
                row.append(f"{c['accuracy']:.1f} / {c['validity']:.1f}" if c else "-")
            print("| " + " | ".join(row) + " |")
    print("\nCells: accuracy / validity, in %. Pairs per cell: 200; base 5-shot cells "
          "average 3 reruns, all others 1.")
    print(ceilings(args.results))


def ceilings(results: Path) -> str:
    """What the labels allow on each split's sample (see `ara eval ceiling`)."""
    from ara.data import load_or_prepare, load_split, registered_version
    from ara.eval.ceiling import split_ceiling

    lines = []
    for split in ("paper", "disjoint"):
        run = results / f"base-270m-{split}-zeroshot" / "run.json"
        if not run.exists():
            continue
        record = json.loads(run.read_text())
        c = record["config"]
        # The ceiling of the data the run was judged on, which a later version may not be.
        version = record.get("data", {}).get("version")
        if version in (None, registered_version(split, c["data_seed"])):
            data = load_or_prepare(split, c["data_seed"])
        else:  # raises, naming the version, where this machine never prepared it
            data = load_split(split, c["data_seed"], version=version)
        ceiling = split_ceiling(data, c["form"], c["limit"], c["seed"])
        lines.append(f"{split}: a translator that follows the training labels can get at most "
                     f"{ceiling.train_majority}/{ceiling.records} of these pairs right "
                     f"({len(ceiling.conflicts)} inputs are labelled otherwise in training).")
    return "\n".join(lines)


if __name__ == "__main__":
    main()
