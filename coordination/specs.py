"""The specifications robots plan for, built as ASTs of :mod:`ara.grammars`.

Each job is the paper's pick-and-place conjunction (:func:`ara.data.help_requests.pnp_spec`,
where a help request's template spec is built too); the global spec is
``G(!obstacle & actuation)``. Formulas are built here, never parsed from strings; a
helper's translated help request joins them as one more conjunct.
"""

from __future__ import annotations

from collections.abc import Sequence

from ara.coordination.events import Vocabulary
from ara.coordination.planner_dp import Job
from ara.coordination.world import GridWorld
from ara.data.help_requests import pick_ap, place_ap, pnp_spec
from ara.grammars import Always, And, Atom, Formula, Not

OBSTACLE, ACTUATION = "obstacle", "actuation"


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
