"""Self-consistency against greedy decoding, side by side in one run: accuracy and
time per formula on the hand-written suite (never trained on).

    .venv/bin/python bench/self_consistency.py [--model finetuned] [--samples 5]
        [--temperature 0.7] [--out runs/bench/self-consistency.json]

Zero-shot for fine-tuned adapters (5 worked examples otherwise), under the grammar.
The greedy answer is the vote's first answer, so both columns come from the same
generations; the vote's time includes its sampled answers and Spot checks.
"""

from __future__ import annotations

import argparse
import json
import platform
import random
import statistics
from datetime import date
from pathlib import Path

from tqdm import tqdm

from ara.data import load_or_prepare
from ara.eval.translate.models import default_shots, make_backend
from ara.eval.translate.prompt import sample_shots
from ara.eval.translate.repair import translate_consistent
from ara.eval.translate.translator import Translator
from ara.grammars.spot_bridge import judge


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", default="finetuned")
    parser.add_argument("--samples", type=int, default=5)
    parser.add_argument("--temperature", type=float, default=0.7)
    parser.add_argument("--limit", type=int, default=None,
                        help="Instructions per form, sampled with seed 0 (default: all).")
    parser.add_argument("--out", type=Path, default=Path("runs/bench/self-consistency.json"))
    args = parser.parse_args()
    translator = Translator(make_backend(args.model))
    k = default_shots(args.model)
    rows = []
    for form in ("lifted", "grounded"):
        pool = load_or_prepare("compositional", 0).records("train", form)
        shots = sample_shots(pool, k, random.Random(0)) if k else []
        records = load_or_prepare("handwritten").records("test", form)
        if args.limit is not None and args.limit < len(records):
            records = random.Random(0).sample(records, args.limit)
        for r in tqdm(records, desc=form):
            vote = translate_consistent(translator, r.nl, r.aps, shots, args.samples,
                                        args.temperature, seed=0)
            greedy = judge(r.stl, vote.answers[0], timeout_s=10)["equivalent"]
            voted = judge(r.stl, vote.result.stl, timeout_s=10)["equivalent"]
            rows.append({"form": form, "nl": r.nl, "reference": r.stl,
                         "answers": list(vote.answers), "winner": vote.result.stl,
                         "greedy_equivalent": greedy, "vote_equivalent": voted,
                         "agreement": vote.agreement, "greedy_ms": vote.results[0].ms,
                         "vote_ms": vote.ms})
    n = len(rows)
    greedy_acc = 100 * sum(bool(r["greedy_equivalent"]) for r in rows) / n
    vote_acc = 100 * sum(bool(r["vote_equivalent"]) for r in rows) / n
    vote_ms = statistics.median(r["vote_ms"] for r in rows)
    greedy_ms = statistics.median(r["greedy_ms"] for r in rows)
    print("| decoding | accuracy % | median ms per formula |\n|---|---:|---:|")
    print(f"| greedy | {greedy_acc:.1f} | {greedy_ms:.0f} |")
    print(f"| self-consistency, {args.samples} samples, T={args.temperature} | {vote_acc:.1f} "
          f"| {vote_ms:.0f} |")
    print(f"\n{n} hand-written instructions, model {translator.backend.model_id}; "
          f"vote/greedy time ratio {vote_ms / greedy_ms:.1f}")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps({
        "date": date.today().isoformat(), "machine": platform.platform(),
        "model": translator.backend.model_id, "samples": args.samples,
        "temperature": args.temperature, "greedy_accuracy": greedy_acc,
        "vote_accuracy": vote_acc, "greedy_median_ms": greedy_ms, "vote_median_ms": vote_ms,
        "rows": rows}, indent=2) + "\n")


if __name__ == "__main__":
    main()
