"""Latency of `ara translate` as users get it, before and after the compositional
fine-tune, measured side by side in one run on the same sentences.

    .venv/bin/python bench/translate_latency.py [--n 40] [--candidate lora:FILE.gguf ...]

Rows: the earlier default (paper-split adapter, grammar without time bounds), the new
default (compositional adapter; intervals use 0 and the numbers the sentence writes),
the same adapter with any bound up to 1000 (a grammar of two rules per number, which
llguidance compiles for every new set of propositions), and without time bounds.
Zero-shot, greedy, under the grammar, on ``--n`` hand-written grounded instructions
(seed 0), one warm-up call first; the rows take turns sentence by sentence. A formula's
time depends on its length, so tokens per answer are shown too.
Each ``--candidate`` (any ``--model`` value, e.g. an adapter not shipped yet) adds a row
with the default grammar, so a candidate is timed beside what ships, in the same run.
Every row keeps its own model loaded for the whole run (about 300 MB each).
``--repair K`` (default 8) adds the default with repair (`ara translate --repair K`),
by samples+edits (the default; it also draws for a complete answer the model doubts),
by edits and by samples: its median is the greedy answer's, its mean carries the extra
work for the few it acts on. The row "ara translate" is what the command does by
default (:func:`~ara.eval.translate.answering.answer`): repair, the model's probability of the
answer it gives (the confidence note; free where repair scored the answer already), and
for a doubted answer the other readings it weighed (Spot checks between them).
"""

from __future__ import annotations

import argparse
import os
import platform
import random
import statistics
import time
from collections.abc import Callable

from tqdm import tqdm

from ara.data import load_or_prepare
from ara.eval.translate.answering import answer
from ara.eval.translate.models import make_backend
from ara.eval.translate.repair import REPAIR_BY, RepairConfig, translate_repaired
from ara.eval.translate.translator import Translator, TranslatorConfig


def timer(translator: Translator, repair: int = 0, by: str = REPAIR_BY[0],
          command: bool = False) -> Callable:
    """One timed answer of a row: its milliseconds and completion tokens (None for the
    whole command, whose answers are several)."""
    def one(r) -> tuple[float, float | None]:
        start = time.perf_counter()
        if command:  # what `ara translate` does, as it does it
            answer(translator, r.nl, r.aps)
            return (time.perf_counter() - start) * 1e3, None
        if repair:
            vote = translate_repaired(translator, r.nl, r.aps, repair=RepairConfig(repair, by))
            return (time.perf_counter() - start) * 1e3, vote.result.completion_tokens
        result = translator.translate(r.nl, r.aps)
        return result.ms, result.completion_tokens
    return one


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=40, help="hand-written instructions")
    ap.add_argument("--candidate", action="append", default=[], metavar="MODEL",
                    help="another --model value to time with the default grammar "
                         "(repeatable), e.g. lora:runs/soup/x/lora.gguf")
    ap.add_argument("--repair", type=int, default=8,
                    help="extra answers for the repair row (0: no such row)")
    args = ap.parse_args()
    records = random.Random(0).sample(load_or_prepare("handwritten").records("test", "grounded"),
                                      args.n)
    rows = [("finetuned-paper", TranslatorConfig(intervals=False), "earlier default",
             "no time bounds", 0),
            ("finetuned", TranslatorConfig(), "default", "bounds the sentence writes", 0),
            *[("finetuned", TranslatorConfig(), f"--repair {args.repair} --repair-by {by}",
               "bounds the sentence writes", (args.repair, by))
              for by in REPAIR_BY if args.repair],
            *[("finetuned", TranslatorConfig(),
               "ara translate: repair, confidence, other readings",
               "bounds the sentence writes", (args.repair, REPAIR_BY[0], True))
              for _ in range(bool(args.repair))],
            ("finetuned", TranslatorConfig(bounds_from_request=False), "--any-bound",
             "any bound up to 1000", 0),
            ("finetuned", TranslatorConfig(intervals=False), "--no-intervals", "no time bounds",
             0),
            *[(model, TranslatorConfig(), "candidate", "bounds the sentence writes", 0)
              for model in args.candidate]]
    # Each row has its own backend, warmed (loaded, its grammar compiled) before any timing;
    # the rows then take turns sentence by sentence, each sentence starting with another row,
    # so that a machine that slows down mid-run slows every row alike.
    timers = []
    for model, config, *_, repair in rows:
        one = timer(Translator(make_backend(model), config), *(repair or (0,)))
        one(records[0])
        timers.append(one)
    ms: list[list[float]] = [[] for _ in rows]
    tokens: list[list[float]] = [[] for _ in rows]
    done = 0
    try:
        for i, r in enumerate(tqdm(records, desc="sentences", unit="sentence")):
            for k in [(i + j) % len(rows) for j in range(len(rows))]:
                took, count = timers[k](r)
                ms[k].append(took)
                if count is not None:
                    tokens[k].append(count)
            done += 1
    except KeyboardInterrupt:  # the sentences every row has answered still make a table
        print(f"interrupted: the table below is of the first {done} sentences")
        ms = [row[:done] for row in ms]
        tokens = [row[:done] for row in tokens]
    if not done:
        return
    print(f"# {done} hand-written grounded instructions, zero-shot, greedy, constrained; "
          f"rows interleaved sentence by sentence; {platform.machine()}, "
          f"{os.cpu_count()} cores")
    print("| model | grammar | median ms/formula | mean ms/formula | tokens/answer | "
          "median vs earlier default |")
    print("|---|---|---:|---:|---:|---:|")
    base = statistics.median(ms[0])
    for (model, _, label, grammar, _), row_ms, row_tokens in zip(rows, ms, tokens,
                                                                  strict=True):
        median = statistics.median(row_ms)
        count = f"{statistics.fmean(row_tokens):.1f}" if row_tokens else "-"
        print(f"| {model} ({label}) | {grammar} | {median:.0f} | "
              f"{statistics.fmean(row_ms):.0f} | {count} | {median / base:.2f} |")


if __name__ == "__main__":
    main()
