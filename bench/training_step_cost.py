"""A training step of the shipped recipe: as configured, and with one setting changed.

    python bench/training_step_cost.py [--steps 10] [--dropout 0.05]

Runs ``--steps`` steps of ``gemma3_270m_nl2tl.yaml``'s ``start`` stage on the embedded
Gemma 3 270M three times in this process, on the same batches (same seed): as
configured, with ``lora.dropout`` set to ``--dropout``, and with ``precision: fp32``.
Prints the median seconds per step of each (the first two steps are warm-up), their
ratios to the recipe's, the precision each computed in, and each step's loss side by
side.

Why these two: a dropout on a LoRA layer masks that layer's whole input (640 to 2,048
values a token, seven layers a block), and drawing random numbers is slow on a CPU; and
on a CPU with AMX or AVX512-BF16 the recipe's ``precision: auto`` multiplies in bf16,
several times as fast as fp32 for the matrix products alone. Writes ``result.json`` into ``--out``.
"""

from __future__ import annotations

import argparse
import json
import shutil
import statistics
import time
from pathlib import Path

import torch

REPO = Path(__file__).resolve().parents[1]
RECIPE = REPO / "training" / "configs" / "gemma3_270m_nl2tl.yaml"


def run(name: str, change: dict, steps: int, out: Path) -> dict:
    from ara.training.config import TrainConfig, read_config
    from ara.training.recipe import LoRAFinetuneRecipe
    from ara.training.run_folder import log_rows
    from ara.training.stages import StagedRecipe

    recipe = StagedRecipe.from_dict(read_config(RECIPE))
    settings = recipe.train_config(recipe.stages[0]).to_dict()
    for key, value in change.items():
        section, _, field = key.rpartition(".")
        (settings[section] if section else settings)[field] = value
    folder = out / name
    shutil.rmtree(folder, ignore_errors=True)
    config = TrainConfig.from_dict({**settings, "out": str(folder), "max_steps": steps,
                                    "eval_pairs": 0, "checkpoint_every": 10**6})
    start = time.perf_counter()
    training = LoRAFinetuneRecipe(config)
    training.setup()
    losses = training.train()
    wall = time.perf_counter() - start
    log = log_rows(folder / "train_log.jsonl")
    timed = log[2:] or log
    return {"run": name, "lora_dropout": settings["lora"]["dropout"],
            "dtype": str(training.dtype).removeprefix("torch."), "steps": len(log),
            "median_s_per_step": statistics.median(row["seconds"] for row in timed),
            "losses": losses, "wall_s": round(wall, 1)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=10, help="steps per run (default 10)")
    ap.add_argument("--dropout", type=float, default=0.05,
                    help="the LoRA dropout to compare the recipe's with (default 0.05)")
    ap.add_argument("--out", type=Path, default=REPO / "runs" / "bench" / "training-step-cost",
                    help="scratch and result folder")
    args = ap.parse_args()
    if args.steps < 3:
        ap.error("--steps must be at least 3 (two are warm-up)")
    if not 0 <= args.dropout < 1:
        ap.error("--dropout must be in [0, 1)")
    rows = [run("recipe", {}, args.steps, args.out),
            run(f"dropout {args.dropout}", {"lora.dropout": args.dropout}, args.steps,
                args.out),
            run("fp32", {"precision": "fp32"}, args.steps, args.out)]
    mine = rows[0]
    for row in rows:
        row["time_vs_recipe"] = round(row["median_s_per_step"] / mine["median_s_per_step"], 2)
    result = {"rows": rows, "torch": torch.__version__, "threads": torch.get_num_threads(),
              "cpu_amx": getattr(torch.cpu, "_is_amx_tile_supported", lambda: False)(),
              "cpu_avx512_bf16": getattr(torch.cpu, "_is_avx512_bf16_supported",
                                         lambda: False)(),
              "date": time.strftime("%Y-%m-%d", time.gmtime())}
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "result.json").write_text(json.dumps(result, indent=2) + "\n")
    print("| run | lora dropout | computes in | median s/step | time vs the recipe's |")
    print("|---|---:|---|---:|---:|")
    for r in rows:
        print(f"| {r['run']} | {r['lora_dropout']} | {r['dtype']} | "
              f"{r['median_s_per_step']:.2f} | {r['time_vs_recipe']:.2f}x |")
    print("\nlosses step by step: " + ", ".join(r["run"] for r in rows))
    for i, losses in enumerate(zip(*(r["losses"] for r in rows), strict=True), start=1):
        print(f"  step {i:3d}  " + "  ".join(f"{x:.4f}" for x in losses))

if __name__ == "__main__":
    main()
