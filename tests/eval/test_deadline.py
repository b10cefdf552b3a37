"""A time budget for one answer: ara.eval.translate.deadline."""

import math
import time

import pytest

from ara.eval.translate.deadline import UNBOUNDED, Deadline


def spent_deadline() -> Deadline:
    """A budget of one second, started two seconds ago."""
    return Deadline(1.0, start=time.perf_counter() - 2.0)


@pytest.mark.parametrize("s", [None, 0])  # both mean no budget
def test_an_unbounded_deadline_never_runs_out(s):
    """Tests that a deadline without a budget has all the time there is, leaves a
    check its own limit, and never says it ran out."""
    deadline = Deadline(s)
    assert deadline.left() == math.inf and not deadline.expired
    assert not deadline.spent() and not deadline.ran_out
    assert deadline.within(2.0) == 2.0 and deadline.within(None) is None
    assert not UNBOUNDED.spent() and not UNBOUNDED.ran_out  # so every call may share it


def test_a_deadline_counts_down_from_its_start():
    """Tests that the time left is the budget less the time since the start."""
    # A budget of minutes, so that a busy machine's pause before the asserts changes
    # nothing they check.
    deadline = Deadline(1000.0, start=time.perf_counter() - 400.0)
    assert 500.0 < deadline.left() <= 600.0
    assert deadline.within(2.0) == 2.0  # the check's own limit is the lesser
    assert 500.0 < deadline.within(3000.0) <= 600.0  # the time left is
    assert 500.0 < deadline.within(None) <= 600.0
    assert deadline.elapsed_ms >= 400_000.0
    assert not deadline.spent() and not deadline.ran_out


def test_a_spent_deadline_says_so_only_when_a_step_asks():
    """Tests that a spent budget leaves no time and that ran_out is set by the first
    step that asks whether it may run, not by the clock alone."""
    deadline = spent_deadline()
    assert deadline.left() == 0.0 and deadline.expired and deadline.within(2.0) == 0.0
    assert not deadline.ran_out  # nothing was cut short yet
    assert deadline.spent() and deadline.ran_out
