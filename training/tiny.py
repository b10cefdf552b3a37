"""A tiny Gemma 3 built from a config: for tests, golden losses and smoke runs.

Two layers, 32 wide, random weights from a fixed seed, and the real 262k tokenizer of
the prepared base model, so prompts and answers tokenize as in a real run. Nothing is
downloaded. ``query_pre_attn_scalar`` equals ``head_dim`` as in every Gemma 3, which
llama.cpp's converter assumes.
"""

from __future__ import annotations

from pathlib import Path


def build_tiny_gemma(folder: str | Path, tokenizer_dir: str | Path, seed: int = 0) -> str:
    """Write the tiny model and the tokenizer into ``folder``; returns its path."""
    import torch
    from transformers import AutoTokenizer, Gemma3ForCausalLM, Gemma3TextConfig

    torch.manual_seed(seed)
    tokenizer = AutoTokenizer.from_pretrained(tokenizer_dir)
    config = Gemma3TextConfig(vocab_size=len(tokenizer), hidden_size=32, intermediate_size=64,
                              num_hidden_layers=2, num_attention_heads=2, num_key_value_heads=1,
                              head_dim=16, query_pre_attn_scalar=16, sliding_window=64,
                              max_position_embeddings=1024)
    Gemma3ForCausalLM(config).save_pretrained(folder)
    tokenizer.save_pretrained(folder)
    return str(folder)


#: The run the golden losses come from (``scripts/golden_losses.py``).
GOLDEN_RUN = {"seed": 0, "checkpoint_every": 100, "eval_pairs": 0, "max_steps": 2,
              "precision": "fp32",  # the same losses on every machine
              "lora": {"r": 4, "alpha": 8, "dropout": 0.0},
              "optim": {"lr": 5e-3, "batch_size": 4, "warmup_steps": 0},
              "data": {"forms": ["lifted"], "limit": 8}}
