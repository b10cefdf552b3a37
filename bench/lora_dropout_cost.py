"""What LoRA dropout costs a training step of the shipped recipe, side by side.

    python bench/lora_dropout_cost.py [--steps 10] [--dropout 0.05]

Runs ``--steps`` steps of ``gemma3_270m_nl2tl.yaml``'s ``start`` stage on the embedded
Gemma 3 270M, once as configured and once with ``lora.dropout`` set to ``--dropout``,
one after the other in this process, on the same batches (same seed). Prints the
median seconds per step of each (the first two steps are warm-up), their ratio, and
each step's loss side by side.

Why it is worth measuring: a dropout on a LoRA layer masks that layer's whole input
(640 to 2,048 values a token, seven layers a block, q, k and v each drawing their own
mask), and drawing random numbers is slow on a CPU, so the masks can cost a step as
much as a large share of its matrix products. Writes ``result.json`` into ``--out``.
"""

from __future__ import annotations

import argparse
import json
import shutil
import statistics
import time
from pathlib import Path

import torch
import yaml

REPO = Path(__file__).resolve().parents[1]
RECIPE = REPO / "training" / "configs" / "gemma3_270m_nl2tl.yaml"


def run(name: str, dropout: float | None, steps: int, out: Path) -> dict:
    from ara.training.config import TrainConfig
    from ara.training.recipe import LoRAFinetuneRecipe
    from ara.training.stages import StagedRecipe

    recipe = StagedRecipe.from_dict(yaml.safe_load(RECIPE.read_text()))
    settings = recipe.train_config(recipe.stages[0]).to_dict()
    if dropout is not None:
        settings["lora"]["dropout"] = dropout
    folder = out / name
    shutil.rmtree(folder, ignore_errors=True)
    config = TrainConfig.from_dict({**settings, "out": str(folder), "max_steps": steps,
                                    "eval_pairs": 0, "checkpoint_every": 10**6})
    start = time.perf_counter()
    training = LoRAFinetuneRecipe(config)
    training.setup()
    losses = training.train()
    wall = time.perf_counter() - start
    log = [json.loads(line) for line in (folder / "train_log.jsonl").read_text().splitlines()]
    timed = log[2:] or log
    return {"run": name, "lora_dropout": settings["lora"]["dropout"], "steps": len(log),
            "median_s_per_step": statistics.median(row["seconds"] for row in timed),
            "losses": losses, "wall_s": round(wall, 1)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=10, help="steps per run (default 10)")
    ap.add_argument("--dropout", type=float, default=0.05,
                    help="the LoRA dropout to compare the recipe's with (default 0.05)")
    ap.add_argument("--out", type=Path, default=REPO / "runs" / "bench" / "lora-dropout",
                    help="scratch and result folder")
    args = ap.parse_args()
    if args.steps < 3:
        ap.error("--steps must be at least 3 (two are warm-up)")
    if not 0 <= args.dropout < 1:
        ap.error("--dropout must be in [0, 1)")
    rows = [run("recipe", None, args.steps, args.out),
            run(f"dropout-{args.dropout}", args.dropout, args.steps, args.out)]
    mine, other = rows
    pairs = list(zip(mine["losses"], other["losses"], strict=True))
    result = {"rows": rows,
              "recipe_speed_ratio": other["median_s_per_step"] / mine["median_s_per_step"],
              "max_loss_gap": max(abs(a - b) for a, b in pairs),
              "torch": torch.__version__, "threads": torch.get_num_threads(),
              "date": time.strftime("%Y-%m-%d", time.gmtime())}
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "result.json").write_text(json.dumps(result, indent=2) + "\n")
    print("| run | lora dropout | median s/step | wall s |\n|---|---:|---:|---:|")
    for r in rows:
        print(f"| {r['run']} | {r['lora_dropout']} | {r['median_s_per_step']:.2f} "
              f"| {r['wall_s']} |")
    print(f"\nthe recipe's step takes {1 / result['recipe_speed_ratio']:.2f}x the time of one "
          f"with dropout {args.dropout}; losses step by step:")
    for i, (a, b) in enumerate(pairs, start=1):
        print(f"  step {i:3d}  recipe {a:.4f}  dropout {args.dropout} {b:.4f}  "
              f"gap {abs(a - b):.4f}")


if __name__ == "__main__":
    main()
