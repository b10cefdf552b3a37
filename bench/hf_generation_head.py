"""Greedy answers through the transformers backend by precision, and what feeding the
output layer two-dimensional rows (:mod:`ara.output_layer`) saves in bf16.

    .venv/bin/python bench/hf_generation_head.py [--n 12]

Whether the recipe's held-out check should generate in the precision it trains in (bf16
on a CPU with AMX) or cast to fp32 first (what it does on a CPU). Three rows on the
embedded Gemma 3 270M (the HF folder `ara model prepare` makes), zero-shot under the
grammar, on ``--n`` hand-written grounded instructions (seed 0), side by side in one
process after one warm-up answer: fp32 and bf16 as the backend runs them, and bf16 with
the output layer given the usual ``(1, tokens, hidden)`` input, whose batched product
copies the transposed 262k-row layer at every token. Prints the median and mean ms per
answer, the ratios to fp32, and how many answers agree with fp32's. The base model runs
without an adapter; the held-out check's PEFT model (fp32 LoRA factors over the base)
adds to bf16's cost, not fp32's.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import platform
import random
import statistics


@contextlib.contextmanager
def picked_after(model, pick):
    """The output layer on its usual 3-D input, as before :mod:`ara.output_layer`; the
    backend's rows are picked from its output instead of its input."""
    head = getattr(model, "module", model).get_output_embeddings()
    hook = head.register_forward_hook(lambda _, args, out: pick(out))
    try:
        yield
    finally:
        hook.remove()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=12, help="hand-written instructions")
    args = ap.parse_args()

    from ara.data import load_or_prepare
    from ara.eval.translate.backends import hf_backend
    from ara.eval.translate.translator import Translator
    from ara.training.hf_model import default_hf_dir, is_prepared

    folder = default_hf_dir()
    if not is_prepared(folder):
        raise SystemExit(f"error: no HF folder at {folder}; run `ara model prepare` first")
    records = random.Random(0).sample(load_or_prepare("handwritten").records("test", "grounded"),
                                      args.n)
    rows = [("fp32", "float32", True), ("bf16", "bfloat16", True),
            ("bf16, 3-D head input", "bfloat16", False)]
    results = {}
    for name, dtype, two_d in rows:
        translator = Translator(hf_backend.HFBackend(str(folder), device="cpu", dtype=dtype))
        keep = hf_backend.output_rows
        if not two_d:
            hf_backend.output_rows = picked_after
        try:
            translator.translate(records[0].nl, records[0].aps)  # warm-up
            runs = [translator.translate(r.nl, r.aps) for r in records]
        finally:
            hf_backend.output_rows = keep
        results[name] = runs
    base = results["fp32"]
    print(f"# {args.n} hand-written grounded instructions, zero-shot, greedy, constrained; "
          f"{platform.machine()}, {os.cpu_count()} cores")
    print("| row | median ms/answer | mean ms/answer | median vs fp32 | answers as fp32's |")
    print("|---|---:|---:|---:|---:|")
    base_median = statistics.median(r.ms for r in base)
    for name, runs in results.items():
        median = statistics.median(r.ms for r in runs)
        same = sum(a.stl == b.stl for a, b in zip(runs, base, strict=True))
        print(f"| {name} | {median:.0f} | {statistics.fmean(r.ms for r in runs):.0f} | "
              f"{median / base_median:.2f}x | {same}/{len(runs)} |")


if __name__ == "__main__":
    main()
