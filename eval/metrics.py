"""The paper's metrics over sample records, as pure functions.

Within one run (a rerun at one shot count), every variant translated the same test
pairs. Then:

* validity of a variant: the share of its outputs that parse;
* accuracy: the share logically equivalent to the reference, over the pairs that are
  valid under *all* variants of that run, so variants are compared on the same set;
* containment: of the outputs in that set that are valid but wrong, the share that
  imply the reference (the model asked for something stronger, never weaker).

Each is then averaged over reruns (mean and sample standard deviation). Pairs whose
Spot check ran out of time are left out of accuracy and containment and counted.
"""

from __future__ import annotations

import statistics
from collections import Counter, defaultdict
from collections.abc import Iterable
from typing import TypedDict

from ara.eval.translate.checks import KINDS, gaps
from ara.eval.translate.request import Request
from ara.grammars import parse
from ara.stats import describe


class Stat(TypedDict):
    """A metric over reruns, in percent (latency: milliseconds); NaN when none."""

    mean: float
    std: float
    median: float
    n: int


class VariantResult(TypedDict):
    """One variant at one shot count."""

    variant: str
    shots: int
    validity: Stat
    accuracy: Stat
    containment: Stat
    latency_ms: Stat
    common_pairs: Stat
    undecided: int


def _stat(values: list[float]) -> Stat:
    return Stat(**describe(values, empty=float("nan")))


def _pct(k: int, n: int) -> float | None:
    return 100.0 * k / n if n else None


def score(samples: Iterable[dict]) -> list[VariantResult]:
    """Metrics per (variant, shots) from sample records.

    Each sample needs ``variant``, ``shots``, ``rerun``, ``uid``, ``valid``,
    ``equivalent`` (bool, or ``None`` when undecided), ``implies`` and ``ms``.
    """
    runs: dict[tuple[int, int], dict[str, dict[str, dict]]] = defaultdict(
        lambda: defaultdict(dict))
    for s in samples:
        runs[(s["shots"], s["rerun"])][s["variant"]][s["uid"]] = s
    per: dict[tuple[str, int], dict[str, list]] = defaultdict(lambda: defaultdict(list))
    undecided: dict[tuple[str, int], int] = defaultdict(int)
    for (shots, _rerun), by_variant in sorted(runs.items()):
        uid_sets = [set(v) for v in by_variant.values()]
        shared = set.intersection(*uid_sets)  # pairs every variant has translated
        common = {u for u in shared if all(by_variant[v][u]["valid"] for v in by_variant)}
        for variant, by_uid in by_variant.items():
            key = (variant, shots)
            rows = [by_uid[u] for u in sorted(shared)]
            decided = [by_uid[u] for u in sorted(common) if by_uid[u]["equivalent"] is not None]
            undecided[key] += len(common) - len(decided)
            wrong = [s for s in decided if not s["equivalent"]]
            for name, value in (
                ("validity", _pct(sum(s["valid"] for s in rows), len(rows))),
                ("accuracy", _pct(sum(s["equivalent"] for s in decided), len(decided))),
                ("containment", _pct(sum(bool(s["implies"]) for s in wrong), len(wrong))),
                ("latency_ms", statistics.fmean(s["ms"] for s in rows) if rows else None),
                ("common_pairs", float(len(common))),
            ):
                if value is not None:
                    per[key][name].append(value)
    return [
        VariantResult(variant=v, shots=k, undecided=undecided[(v, k)],
                      **{m: _stat(per[(v, k)][m]) for m in
                         ("validity", "accuracy", "containment", "latency_ms", "common_pairs")})
        for (v, k) in sorted(per, key=lambda key: (key[1], _variant_order(key[0])))
    ]


def _variant_order(name: str) -> tuple[int, str]:
    return (len(name), name)


def overhead(results: list[VariantResult]) -> dict[str, float]:
    """Constrained-vs-unconstrained latency ratio at each shot count: X+C over X, and C
    over none.

    Returns:
        ``{"F+P+C / F+P @ 5 shots": 1.03, "C / none @ 0 shots": 1.1, ...}`` for every pair
        present.
    """
    by_key = {(r["variant"], r["shots"]): r["latency_ms"]["mean"] for r in results}
    ratios = {}
    for (variant, shots), ms in sorted(by_key.items()):
        if variant.endswith("+C") or variant == "C":
            base = variant[:-2] if variant.endswith("+C") else "none"
            if (base, shots) in by_key and by_key[(base, shots)]:
                ratios[f"{variant} / {base} @ {shots} shots"] = round(ms / by_key[(base, shots)], 3)
    return ratios


def gap_precision(references: Iterable = (),
                  answers: Iterable[dict] = ()) -> dict[str, Counter]:
    """How often each kind of gap (:data:`~ara.eval.translate.checks.KINDS`) flags a right answer,
    and a wrong one: how precise the signal repair acts on is.

    Args:
        references: Pairs with ``nl``, ``aps`` and a reference ``stl``; each is a right
            answer, so each one flagged is a right answer repair would try to mend.
        answers: Sample lines of a run (``nl``, ``aps``, ``stl``, ``equivalent``); those
            with no formula are skipped.

    Returns:
        Per kind, a count of ``references`` flagged, and of the ``right`` and ``wrong``
        answers flagged.
    """
    counts = {kind: Counter() for kind in KINDS}
    for r in references:
        for kind in gaps(Request.of(r.nl, r.aps), parse(r.stl)).kinds():
            counts[kind]["references"] += 1
    for row in answers:
        if row.get("stl"):
            verdict = "right" if row["equivalent"] else "wrong"
            for kind in gaps(Request.of(row["nl"], row["aps"]), parse(row["stl"])).kinds():
                counts[kind][verdict] += 1
    return counts
