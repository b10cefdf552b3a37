"""One status vocabulary for solver results, robot plans and fleet schedules.

A MILP solve, the DP planner, the event planner and the Oracle each say how they ended
in these words, so a caller (the protocol, Experiment 2's rows) never translates
between them.
"""

from __future__ import annotations

from typing import Literal, get_args

Status = Literal[
    "optimal",      # proven best
    "feasible",     # a solution, not proven best (a solver stopped at its time limit)
    "heuristic",    # a solution from a heuristic (the ILS Oracle), never proven
    "infeasible",   # proven to have no solution (e.g. not within the makespan cap)
    "over_cap",     # the best plan exceeds the makespan cap (the DP planner)
    "unreachable",  # a cell the plan needs cannot be reached
    "time_limit",   # stopped without a solution
    "error",        # the solver failed; its message says why
]
STATUSES: tuple[str, ...] = get_args(Status)
#: Statuses that come with a plan or schedule to act on.
WITH_SOLUTION = frozenset({"optimal", "feasible", "heuristic"})


def checked(status: str) -> Status:
    """``status`` if it is one of :data:`STATUSES`; a ValueError naming them otherwise."""
    if status not in STATUSES:
        raise ValueError(f"unknown status {status!r}; one of {', '.join(STATUSES)}")
    return status  # type: ignore[return-value]
