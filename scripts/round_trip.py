"""Round trip: explain a formula in English, translate the English back, and ask Spot
whether the two formulas are the same.

    .venv/bin/python scripts/round_trip.py [--model finetuned] [--limit 100]
        [--out runs/bench/round-trip.json]

Formulas: the hand-written suite's references and the compositional test side's
(lifted and grounded, ``--limit`` of each, seed 0). ``ara stl explain`` reads a formula
with the first phrasing of every construct, which training uses, but the formulas and
their shapes are ones the model never trained on. Zero-shot, under the grammar.
"""

from __future__ import annotations

import argparse
import json
import platform
import random
from datetime import date
from pathlib import Path

from tqdm import tqdm

from ara.data import load_or_prepare
from ara.eval.translate.models import default_shots, make_backend
from ara.eval.translate.prompt import sample_shots
from ara.eval.translate.translator import Translator
from ara.grammars import parse
from ara.grammars.english import explain
from ara.grammars.spot_bridge import judge


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", default="finetuned")
    parser.add_argument("--limit", type=int, default=100, help="Formulas per source and form.")
    parser.add_argument("--out", type=Path, default=Path("runs/bench/round-trip.json"))
    args = parser.parse_args()
    sources = {}
    for split in ("handwritten", "compositional"):
        for form in ("lifted", "grounded"):
            records = load_or_prepare(split, 0).records("test", form)
            sources[f"{split}-{form}"] = random.Random(0).sample(
                records, min(args.limit, len(records)))
    translator = Translator(make_backend(args.model))
    k = default_shots(args.model)
    pool = load_or_prepare("compositional", 0).records("train", "grounded")
    shots = sample_shots(pool, k, random.Random(0)) if k else []
    rows = []
    for name, records in sources.items():
        for r in tqdm(records, desc=name, unit="formula"):
            english = explain(parse(r.stl))
            result = translator.translate(english, r.aps, shots)
            verdict = judge(r.stl, result.stl, timeout_s=10)
            rows.append({"source": name, "stl": r.stl, "english": english,
                         "back": result.stl, "equivalent": verdict["equivalent"]})
    print("| formulas | round trip equivalent | of |\n|---|---:|---:|")
    for name in sources:
        mine = [r for r in rows if r["source"] == name]
        print(f"| {name} | {sum(bool(r['equivalent']) for r in mine)} | {len(mine)} |")
    total = sum(bool(r["equivalent"]) for r in rows)
    print(f"\nall: {total}/{len(rows)} ({100 * total / len(rows):.1f}%), "
          f"model {translator.backend.model_id}, {k} shots")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps({
        "date": date.today().isoformat(), "machine": platform.platform(),
        "model": translator.backend.model_id, "shots": k, "equivalent": total,
        "formulas": len(rows), "rows": rows}, indent=2) + "\n")


if __name__ == "__main__":
    main()
