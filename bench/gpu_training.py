"""Seconds per step and peak GPU memory of the real training recipe, per model size.

    python bench/gpu_training.py --tokenizer DIR [--archs tiny,270m,12b] [--steps 30]

For each architecture, a model with Gemma 3's published shape and random weights is
written to a scratch folder (no download: the weights' values do not change the time
or the memory of a step), then ``ara train``'s recipe runs ``--steps`` steps on it with
the settings of the config that architecture ships with:

* ``tiny``: the 2-layer test model, the CPU config's batch (a smoke run of the GPU path);
* ``270m``: the first stage of ``gemma3_270m_nl2tl.yaml`` (what the shipped recipe's
  steps take on this GPU);
* ``12b``: ``gemma3_12b_lora_gpu.yaml`` (batch 16, bf16; what one GPU needs for it).

Prints one table row per architecture: median seconds per step (first 3 steps are
warm-up), peak memory torch allocated, trainable parameters, and the loss of the first
and last step (random weights: the loss only has to fall). ``--tokenizer`` is a folder
with Gemma 3's tokenizer (``ara model prepare`` writes one); data splits are prepared
from the vendored raw files.
"""

from __future__ import annotations

import argparse
import json
import statistics
import tempfile
import time
from pathlib import Path

import torch

REPO = Path(__file__).resolve().parents[1]

#: Gemma 3's text configurations (layer counts and widths as published).
ARCHS = {
    "tiny": dict(hidden_size=32, intermediate_size=64, num_hidden_layers=2,
                 num_attention_heads=2, num_key_value_heads=1, head_dim=16,
                 query_pre_attn_scalar=16, sliding_window=64),
    "270m": dict(hidden_size=640, intermediate_size=2048, num_hidden_layers=18,
                 num_attention_heads=4, num_key_value_heads=1, head_dim=256,
                 query_pre_attn_scalar=256, sliding_window=512),
    "12b": dict(hidden_size=3840, intermediate_size=15360, num_hidden_layers=48,
                num_attention_heads=16, num_key_value_heads=8, head_dim=256,
                query_pre_attn_scalar=256, sliding_window=1024),
}
CONFIGS = {"tiny": "gemma3_270m_nl2tl.yaml",
           "270m": "gemma3_270m_nl2tl.yaml",
           "12b": "gemma3_12b_lora_gpu.yaml"}


def random_model(arch: str, tokenizer_dir: Path, folder: Path) -> Path:
    """Write a Gemma 3 of ``arch``'s shape with random bf16 weights, built on the GPU."""
    from transformers import AutoTokenizer, Gemma3ForCausalLM, Gemma3TextConfig

    tokenizer = AutoTokenizer.from_pretrained(tokenizer_dir)
    config = Gemma3TextConfig(vocab_size=len(tokenizer), max_position_embeddings=8192,
                              **ARCHS[arch])
    torch.manual_seed(0)
    torch.set_default_dtype(torch.bfloat16)  # 12B in fp32 would not fit beside its copy
    try:
        with torch.device("cuda"):
            model = Gemma3ForCausalLM(config)
    finally:
        torch.set_default_dtype(torch.float32)
    model.save_pretrained(folder)
    tokenizer.save_pretrained(folder)
    del model
    torch.cuda.empty_cache()
    return folder


def run(arch: str, steps: int, tokenizer_dir: Path, scratch: Path) -> dict:
    from ara.data.store import prepare
    from ara.training.config import TrainConfig, read_config
    from ara.training.recipe import LoRAFinetuneRecipe
    from ara.training.run_folder import log_rows
    from ara.training.stages import StagedRecipe, is_staged

    shipped = read_config(REPO / "training" / "configs" / CONFIGS[arch])
    if is_staged(shipped):  # a recipe: its first stage's run
        recipe = StagedRecipe.from_dict(shipped)
        shipped = recipe.train_config(recipe.stages[0]).to_dict()
    prepare(shipped["data"]["split"], shipped["data"]["seed"])
    model_dir = random_model(arch, tokenizer_dir, scratch / f"{arch}-model")
    config = TrainConfig.from_dict({**shipped, "base_model": str(model_dir),
                                    "out": str(scratch / f"{arch}-run"), "max_steps": steps,
                                    "eval_pairs": 0, "checkpoint_every": 10**6})
    torch.cuda.reset_peak_memory_stats()
    start = time.perf_counter()
    recipe = LoRAFinetuneRecipe(config)
    recipe.setup()
    losses = recipe.train()
    wall = time.perf_counter() - start
    log = log_rows(scratch / f"{arch}-run" / "train_log.jsonl")
    seconds = [row["seconds"] for row in log[3:]] or [row["seconds"] for row in log]
    return {"arch": arch, "config": CONFIGS[arch], "steps": len(log),
            "batch": shipped["optim"]["batch_size"],
            "median_s_per_step": statistics.median(seconds),
            "peak_gib": torch.cuda.max_memory_allocated() / 2**30,
            "trainable": sum(p.numel() for p in recipe.model.parameters() if p.requires_grad),
            "first_loss": losses[0], "last_loss": losses[-1], "wall_s": wall,
            "torch": torch.__version__, "device": torch.cuda.get_device_name()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tokenizer", type=Path, required=True,
                    help="folder with Gemma 3's tokenizer files")
    ap.add_argument("--archs", default="tiny,270m,12b")
    ap.add_argument("--steps", type=int, default=30)
    ap.add_argument("--json", type=Path, help="also write the rows here")
    args = ap.parse_args()
    if not torch.cuda.is_available():
        raise SystemExit("error: no CUDA device; this bench measures the GPU path")
    print(f"# {torch.cuda.get_device_name()}, torch {torch.__version__}; random weights, "
          f"{args.steps} steps each")
    print("| model | config | batch | median s/step | peak GiB | trainable | loss first -> last |")
    print("|---|---|---:|---:|---:|---:|---|")
    rows = []
    with tempfile.TemporaryDirectory() as scratch:
        for arch in args.archs.split(","):
            row = run(arch, args.steps, args.tokenizer, Path(scratch))
            rows.append(row)
            print(f"| {arch} | {row['config']} | {row['batch']} | "
                  f"{row['median_s_per_step']:.3f} | {row['peak_gib']:.1f} | "
                  f"{row['trainable'] / 1e6:.1f}M | {row['first_loss']:.2f} -> "
                  f"{row['last_loss']:.2f} |", flush=True)
    if args.json:
        args.json.write_text(json.dumps(rows, indent=2) + "\n")


if __name__ == "__main__":
    main()
