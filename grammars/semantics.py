"""Brute-force Boolean semantics on lasso words, straight from the definitions.

A lasso word ``prefix loop loop loop ...`` is the finite representation of an
infinite discrete-time trace. This evaluator is deliberately naive (it quantifies
over time steps exactly as the definitions read) so that it can serve as the
independent reference for the Spot translation, bounded until included.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

from ara.grammars.ast import (
    Always,
    And,
    Atom,
    Const,
    Eventually,
    Formula,
    Iff,
    Implies,
    Next,
    Not,
    Or,
    Until,
)


@dataclass(frozen=True)
class Lasso:
    """The infinite trace ``prefix + loop + loop + ...``.

    Args:
        prefix: Letters before the loop; each letter is the set of true propositions.
        loop: The repeated letters, non-empty.
    """

    prefix: tuple[frozenset[str], ...]
    loop: tuple[frozenset[str], ...]

    def __post_init__(self) -> None:
        if not self.loop:
            raise ValueError("a lasso needs a non-empty loop")

    @property
    def period(self) -> int:
        return len(self.prefix) + len(self.loop)

    def fold(self, t: int) -> int:
        """The step in ``[0, period)`` whose suffix equals the suffix at step ``t``."""
        n = len(self.prefix)
        return t if t < n else n + (t - n) % len(self.loop)

    def letter(self, t: int) -> frozenset[str]:
        t = self.fold(t)
        n = len(self.prefix)
        return self.prefix[t] if t < n else self.loop[t - n]


def holds(formula: Formula, word: Lasso, t: int = 0) -> bool:
    """Whether ``formula`` holds on ``word`` at step ``t``."""
    return _holds(formula, word, word.fold(t))


@cache
def _holds(f: Formula, w: Lasso, t: int) -> bool:
    # Steps past t + period repeat ones already seen, so an unbounded search for a
    # witness may stop there.
    horizon = t + w.period
    if isinstance(f, Atom):
        return f.name in w.letter(t)
    if isinstance(f, Const):
        return f.value
    if isinstance(f, Not):
        return not holds(f.arg, w, t)
    if isinstance(f, And):
        return all(holds(a, w, t) for a in f.args)
    if isinstance(f, Or):
        return any(holds(a, w, t) for a in f.args)
    if isinstance(f, Implies):
        return (not holds(f.lhs, w, t)) or holds(f.rhs, w, t)
    if isinstance(f, Iff):
        return holds(f.lhs, w, t) == holds(f.rhs, w, t)
    if isinstance(f, Next):
        return holds(f.arg, w, t + 1)
    lo, hi = (0, None) if f.interval is None else (f.interval.lo, f.interval.hi)
    last = t + hi if hi is not None else t + lo + horizon
    steps = range(t + lo, last + 1)
    if isinstance(f, Eventually):
        return any(holds(f.arg, w, s) for s in steps)
    if isinstance(f, Always):
        return all(holds(f.arg, w, s) for s in steps)
    if isinstance(f, Until):
        return any(
            holds(f.rhs, w, s) and all(holds(f.lhs, w, r) for r in range(t, s)) for s in steps
        )
    raise TypeError(f"not a formula node: {f!r}")
