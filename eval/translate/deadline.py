"""A time budget for one answer, shared by every step that can be cut short.

:func:`~ara.eval.translate.answering.answer` starts one :class:`Deadline` and passes it down:
repair stops drawing, mending and scoring answers when it is spent, and each Spot
check runs for its own limit or the time left, whichever is less. The greedy answer
is always made, so a spent budget still gives an answer: the best found so far.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field


@dataclass
class Deadline:
    """The time left to one answer, from when it was made.

    Attributes:
        s: The budget in seconds; ``None`` or 0: unbounded.
        start: :func:`time.perf_counter` when the answer started (default: now).
        ran_out: Whether a step was skipped or cut short because the budget was spent
            (set by :meth:`spent`), so that an unbounded answer may differ.
    """

    s: float | None = None
    start: float = field(default_factory=time.perf_counter)
    ran_out: bool = False

    def left(self) -> float:
        """Seconds left, 0 once spent; ``math.inf`` when unbounded."""
        if not self.s:
            return math.inf
        return max(0.0, self.s - (time.perf_counter() - self.start))

    @property
    def expired(self) -> bool:
        """Whether the budget is spent (never, when unbounded)."""
        return self.left() <= 0

    @property
    def elapsed_ms(self) -> float:
        """Milliseconds since :attr:`start`."""
        return (time.perf_counter() - self.start) * 1e3

    def spent(self) -> bool:
        """Whether the budget is spent, noted in :attr:`ran_out` if so: ask this before a
        step the answer can do without, and skip the step when it says ``True``."""
        if self.expired:
            self.ran_out = True
            return True
        return False

    def within(self, timeout_s: float | None) -> float | None:
        """A check's time limit within the budget: the less of ``timeout_s`` (``None``:
        none) and the time left; ``None`` when both are unbounded."""
        left = self.left()
        if timeout_s is None:
            return None if left == math.inf else left
        return min(timeout_s, left)


#: A deadline that never comes, the default of every step that takes one; it never
#: changes (only a spent budget sets :attr:`Deadline.ran_out`), so all may share it.
UNBOUNDED = Deadline()
