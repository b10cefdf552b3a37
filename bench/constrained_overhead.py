"""What grammar-constrained decoding and prompt-prefix reuse cost, measured side by side.

For each backend and mask engine, the same test pairs and 5-shot prompts are
translated unconstrained and constrained, and the time per formula is compared.
Then llama.cpp runs the same prompts with and without reusing the KV cache of the
shared few-shot prefix. All numbers come from this one run on this machine.

    .venv/bin/python bench/constrained_overhead.py [--n 20] [--hf] [--builtin]

Time per formula depends on the answer's length, and a constrained answer can differ
from the free one, so the table also reports generated tokens and time per token.
"""

from __future__ import annotations

import argparse
import os
import platform
import random
import statistics

from ara.data import load_split
from ara.eval.translate.prompt import sample_shots
from ara.eval.translate.translator import Translator


def measure(translator: Translator, records, shots, constrained: bool) -> dict:
    translator.translate(records[0].nl, records[0].aps, shots, constrained=constrained)  # warm
    runs = [translator.translate(r.nl, r.aps, shots, constrained=constrained) for r in records]
    ms = [r.ms for r in runs]
    tokens = sum(r.completion_tokens for r in runs)
    return {"ms": statistics.fmean(ms), "tokens": tokens / len(runs),
            "ms_per_token": sum(ms) / max(tokens, 1), "valid": sum(r.valid for r in runs)}


def row(name: str, free: dict, bound: dict) -> str:
    return (f"| {name} | {free['ms']:.0f} | {bound['ms']:.0f} | {bound['ms'] / free['ms']:.3f} | "
            f"{free['ms_per_token']:.1f} | {bound['ms_per_token']:.1f} | "
            f"{bound['ms_per_token'] / free['ms_per_token']:.3f} | "
            f"{free['valid']}/{bound['valid']} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--n", type=int, default=20, help="test pairs")
    ap.add_argument("--hf", action="store_true", help="also the transformers backend")
    ap.add_argument("--builtin", action="store_true",
                    help="also llama.cpp's built-in grammar sampler (slow)")
    args = ap.parse_args()

    from ara.eval.translate.backends.llama_cpp_backend import LlamaCppBackend
    from ara.eval.translate.models import default_model_path

    split = load_split("paper")
    rng = random.Random(0)
    shots = sample_shots(split.records("train", "grounded"), 5, rng)
    records = rng.sample(split.records("test", "grounded"), args.n)
    print(f"# {args.n} grounded test pairs, 5 shots, greedy; {platform.machine()}, "
          f"{os.cpu_count()} cores, {platform.python_version()}")
    print("| backend / mask | free ms/formula | constrained ms/formula | ratio | "
          "free ms/token | constrained ms/token | ratio/token | valid free/constrained |")
    print("|---|---|---|---|---|---|---|---|")
    llama = LlamaCppBackend(default_model_path())
    fast = Translator(llama)
    free = measure(fast, records, shots, constrained=False)
    print(row("llama.cpp / llguidance", free, measure(fast, records, shots, True)), flush=True)
    if args.builtin:
        builtin = Translator(LlamaCppBackend(default_model_path(), mask="llama"))
        print(row("llama.cpp / built-in grammar", free,
                  measure(builtin, records, shots, True)), flush=True)
    if args.hf:
        from ara.eval.translate.backends.hf_backend import HFBackend
        from ara.training.hf_model import prepare_base_model

        folder = str(prepare_base_model())
        hf = Translator(HFBackend(folder))
        hf_free = measure(hf, records, shots, constrained=False)
        print(row("transformers / llguidance", hf_free, measure(hf, records, shots, True)),
              flush=True)
        outlines = Translator(HFBackend(folder, mask="outlines"))
        print(row("transformers / outlines CFG", hf_free,
                  measure(outlines, records, shots, True)), flush=True)

    print("\n| llama.cpp, unconstrained | formulas/s | prompt tokens evaluated per formula |")
    print("|---|---|---|")
    for reuse in (True, False):
        t = Translator(LlamaCppBackend(default_model_path()))
        results = []
        for r in records:
            if not reuse:
                t.backend.llm.n_tokens = 0  # forget the cache: evaluate the whole prompt
            results.append(t.translate(r.nl, r.aps, shots, constrained=False))
        seconds = sum(x.ms for x in results) / 1e3
        evaluated = statistics.fmean(x.prompt_tokens - x.cached_tokens for x in results)
        print(f"| prefix reuse {'on' if reuse else 'off'} | {len(results) / seconds:.2f} | "
              f"{evaluated:.0f} |", flush=True)


if __name__ == "__main__":
    main()
