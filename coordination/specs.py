"""The specifications robots plan for, built as ASTs of :mod:`ara.grammars`.

A pick-and-place job ``j`` is the paper's App. A.2 conjunction over its two action
propositions ``pick_j`` and ``place_j``::

    phi1 = (!place_j) U pick_j              # nothing is placed before it is picked
    phi2 = G(pick_j -> (!others) U place_j)  # carrying j, touch nothing else first
    phi3 = F place_j                        # and it is placed

The global spec is ``G(!obstacle & actuation)``. Formulas are built here, never
parsed from strings; a helper's translated help request joins them as one more
conjunct.
"""

from __future__ import annotations

from collections.abc import Sequence

from ara.coordination.events import Vocabulary
from ara.coordination.planner_dp import Job
from ara.coordination.world import GridWorld
from ara.grammars import Always, And, Atom, Eventually, Formula, Implies, Not, Or, Until

OBSTACLE, ACTUATION = "obstacle", "actuation"


def pick_ap(name: str) -> str:
    return f"pick_{name}"


def place_ap(name: str) -> str:
    return f"place_{name}"


def pnp_spec(name: str, others: Sequence[str] = ()) -> Formula:
    """phi1 & phi2 & phi3 for job ``name``; ``others`` are the other jobs' propositions."""
    pick, place = Atom(pick_ap(name)), Atom(place_ap(name))
    return And((Until(Not(place), pick), carry_alone(pick.name, place.name, others),
                Eventually(place)))


def carry_alone(pick: str, place: str, others: Sequence[str]) -> Formula:
    """phi2: once ``pick`` happens, none of ``others`` before ``place`` (one pallet at a
    time); ``G(pick -> F place)`` when there are no others."""
    carry: Formula = Eventually(Atom(place))  # true U place
    if others:
        blocked = Atom(others[0]) if len(others) == 1 else Or(tuple(Atom(o) for o in others))
        carry = Until(Not(blocked), Atom(place))
    return Always(Implies(Atom(pick), carry))


def global_spec() -> Formula:
    return Always(And((Not(Atom(OBSTACLE)), Atom(ACTUATION))))


def job_names(jobs: Sequence[Job]) -> list[str]:
    """Proposition-safe names: a job's own name, else ``j<index>``."""
    return [job.name or f"j{i}" for i, job in enumerate(jobs)]


def jobs_spec(jobs: Sequence[Job], also_blocked: Sequence[str] = ()) -> Formula:
    """A robot's conjunction of PNP specs for ``jobs`` and the global spec.

    ``also_blocked``: propositions of other parts of the spec (a help job's) that must
    not happen while carrying one of these jobs.
    """
    names = job_names(jobs)
    aps = [ap for n in names for ap in (pick_ap(n), place_ap(n))] + list(also_blocked)
    parts = [pnp_spec(n, [a for a in aps if a not in (pick_ap(n), place_ap(n))])
             for n in names]
    return And((*parts, global_spec())) if parts else global_spec()


def jobs_vocabulary(world: GridWorld, jobs: Sequence[Job]) -> Vocabulary:
    """Event cells and dwell of ``jobs``, the obstacle region, the actuation invariant."""
    events, dwell = {}, {}
    for name, job in zip(job_names(jobs), jobs, strict=True):
        events[pick_ap(name)], events[place_ap(name)] = job.pick, job.drop
        if job.dwell:
            dwell[pick_ap(name)] = job.dwell
    return Vocabulary(events, {OBSTACLE: world.obstacles}, frozenset({ACTUATION}), dwell)
