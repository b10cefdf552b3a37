"""Median seconds per training step, by the number of worked examples its batch showed.

    .venv/bin/python scripts/step_seconds_by_shots.py runs/train/gemma3-270m-lora

Reads ``train_log.jsonl``; for logs written before steps recorded their ``shots``, the
count is drawn again exactly as the recipe drew it (it depends only on seed, epoch and
batch).
"""

from __future__ import annotations

import argparse
import json
import statistics
from collections import defaultdict
from pathlib import Path

from ara.training.config import TrainConfig
from ara.training.dataset import shot_rng


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", type=Path)
    run = parser.parse_args().run
    config = TrainConfig.from_dict(json.loads((run / "run.json").read_text())["config"])
    log = [json.loads(line) for line in (run / "train_log.jsonl").read_text().splitlines()]
    per_epoch = json.loads((run / "run.json").read_text())["data"]["train_examples"]
    per_epoch = -(-per_epoch // config.optim.batch_size)
    seconds = defaultdict(list)
    for entry in log:
        if "seconds" not in entry:
            continue
        epoch, index = divmod(entry["step"] - 1, per_epoch)
        shots = entry.get("shots")
        if shots is None:
            shots = shot_rng(config.seed, epoch, index).choice(list(config.data.shots))
        seconds[shots].append(entry["seconds"])
    print("| shots | steps | median s/step |\n|---:|---:|---:|")
    for k in sorted(seconds):
        print(f"| {k} | {len(seconds[k])} | {statistics.median(seconds[k]):.2f} |")


if __name__ == "__main__":
    main()
