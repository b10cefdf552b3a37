"""Summary statistics, one definition for every table the toolkit writes."""

from __future__ import annotations

import statistics
from collections.abc import Sequence


def describe(values: Sequence[float], digits: int = 4, empty: float | None = None) -> dict:
    """Mean, sample standard deviation (0 for one value), median and count.

    Args:
        values: The numbers.
        digits: Mean and standard deviation are rounded to this many decimals.
        empty: What mean, std and median are when there are no values.
    """
    if not values:
        return {"mean": empty, "std": empty, "median": empty, "n": 0}
    std = statistics.stdev(values) if len(values) > 1 else 0.0
    return {"mean": round(statistics.fmean(values), digits), "std": round(std, digits),
            "median": statistics.median(values), "n": len(values)}
