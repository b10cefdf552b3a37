"""Median seconds per training step, by the number of worked examples its batch showed.

    .venv/bin/python scripts/step_seconds_by_shots.py runs/train/gemma3-270m-lora

Reads the run's ``train_log.jsonl`` (every session of it); a step of ``grad_accum``
micro-batches counts under the worked examples of each.
"""

from __future__ import annotations

import argparse
import statistics
from collections import defaultdict
from pathlib import Path

from ara.training.run_folder import log_rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", type=Path, help="A training run's folder.")
    run = parser.parse_args().run
    seconds = defaultdict(list)
    for entry in log_rows(run / "train_log.jsonl"):
        if "seconds" not in entry or entry.get("shots") is None:
            continue
        shots = entry["shots"]
        for k in shots if isinstance(shots, list) else [shots]:
            seconds[k].append(entry["seconds"])
    if not seconds:
        raise SystemExit(f"error: {run / 'train_log.jsonl'} logs no timed step with its shots")
    print("| shots | steps | median s/step |\n|---:|---:|---:|")
    for k in sorted(seconds):
        print(f"| {k} | {len(seconds[k])} | {statistics.median(seconds[k]):.2f} |")


if __name__ == "__main__":
    main()
