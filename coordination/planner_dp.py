"""Exact per-robot planning of pick-and-place jobs: a DP over job subsets.

For a robot's conjunction of PNP specs, the time to first satisfaction is the length of
the best job order: start -> pick_1 -> drop_1 -> pick_2 -> ... on BFS distances (a job
is done when its drop is reached; waiting never helps). The help job may also keep
the helper ``dwell`` steps at its pick cell. Objectives:

.. math::

    \\text{makespan:}\\; M \\qquad
    \\text{paper:}\\; D + T(\\varphi_{help}) + T(\\varphi_{new}) = D + t_{help} + M \\qquad
    \\text{authors:}\\; T_{all} + D = M + D

(Choe et al., Sec. IV; D is the path length: M less the dwell, since waiting never
helps.) Each is a sum of per-leg weights: a leg of d steps, m of them moving, weighs
d + m, plus d while the help job is not yet done (paper objective). So the DP over
(done jobs, last job) is exact. It is the test oracle for the MILP and the fast path for
experiments. Among equally good orders it returns
one with the least makespan (both are sums over legs, so the pair orders exactly).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from ara.coordination.status import WITH_SOLUTION, Status, checked
from ara.coordination.world import Cell, GridWorld
from ara.errors import ConfigError

OBJECTIVES = ("makespan", "paper", "authors")


@dataclass(frozen=True)
class Job:
    """Pick something up at ``pick`` and put it down at ``drop``.

    Args:
        pick: Pick-up cell.
        drop: Drop-off cell (may equal ``pick``).
        dwell: Steps to stay at ``pick`` (the paper's tau_c for help tasks; 0 by default).
        name: For messages and plots.
    """

    pick: Cell
    drop: Cell
    dwell: int = 0
    name: str = ""

    def __post_init__(self) -> None:
        if self.dwell < 0:
            raise ConfigError(f"job {self.name or (self.pick, self.drop)}: dwell must be "
                              f">= 0 steps, got {self.dwell}")


@dataclass(frozen=True)
class Plan:
    """A robot's best job order, or why there is none.

    Attributes:
        status: ``optimal``, ``unreachable`` (a cell cannot be reached) or ``over_cap``
            (the best makespan exceeds the cap).
        order: Job indices in the order done.
        completion: Step at which each job (by index) is done.
        makespan: Steps until the last job is done (0 with no jobs).
        objective: Value of the objective minimized.
    """

    status: Status
    order: tuple[int, ...] = ()
    completion: tuple[int, ...] = ()
    makespan: int = 0
    objective: int = 0

    def __post_init__(self) -> None:
        checked(self.status)

    @property
    def feasible(self) -> bool:
        return self.status in WITH_SOLUTION


def plan_jobs(world: GridWorld, start: Cell, jobs: list[Job], objective: str = "makespan",
              help_index: int | None = None, cap: int | None = None) -> Plan:
    """The optimal order of ``jobs`` for a robot at ``start``.

    Args:
        world: The grid.
        start: The robot's cell.
        jobs: Its jobs.
        objective: ``makespan``, ``paper`` (needs ``help_index``) or ``authors``.
        help_index: Which job is the help job.
        cap: Largest allowed makespan, or ``None``.
    """
    if objective not in OBJECTIVES:
        raise ConfigError(f"objective must be one of {OBJECTIVES}, got {objective!r}")
    if objective == "paper" and help_index is None:
        raise ConfigError("the paper's objective weighs the help job: give help_index")
    n = len(jobs)
    if n == 0:
        return Plan("optimal")
    legs = leg_lengths(world, start, jobs)
    if legs is None:
        return Plan("unreachable")
    from_start, between = legs.from_start, legs.between
    start_travel, travel = legs.start_travel, legs.travel
    help_bit = 0 if help_index is None else 1 << help_index

    def weight(mask: int, d: int, moved: int) -> int:
        """A leg of d steps, ``moved`` of them travelling (the rest is dwell)."""
        if objective == "makespan":
            return d
        waiting = d if objective == "paper" and not mask & help_bit else 0
        return d + moved + waiting

    full = (1 << n) - 1
    if cap is not None:
        capped = _plan_within_cap(n, from_start, between, start_travel, travel, weight, cap)
        if capped is not None:
            order, cost = capped
            completion = completion_times(order, from_start, between)
            return Plan("optimal", tuple(order), tuple(completion), max(completion), cost)
    inf = float("inf")
    # best[mask][j]: least cost with the jobs of mask done, j last; time[...]: its makespan
    best = [[inf] * n for _ in range(1 << n)]
    time = [[0] * n for _ in range(1 << n)]
    parent: list[list[int]] = [[-1] * n for _ in range(1 << n)]
    for j in range(n):
        best[1 << j][j] = weight(0, from_start[j], start_travel[j])
        time[1 << j][j] = from_start[j]
    for mask in range(1, full + 1):
        for last in range(n):
            cost = best[mask][last]
            if cost == inf:
                continue
            for j in range(n):
                if mask & (1 << j):
                    continue
                d = between[last][j]
                nxt = mask | (1 << j)
                c = cost + weight(mask, d, travel[last][j])
                # ties go to the shorter makespan, as in the MILP's objective
                if c < best[nxt][j] or (c == best[nxt][j]
                                        and time[mask][last] + d < time[nxt][j]):
                    best[nxt][j], time[nxt][j], parent[nxt][j] = c, time[mask][last] + d, last
    last = min(range(n), key=lambda j: (best[full][j], time[full][j], j))
    order = _unwind(parent, full, last)
    completion = completion_times(order, from_start, between)
    makespan = max(completion)
    if cap is not None and makespan > cap:
        return Plan("over_cap", tuple(order), tuple(completion), makespan, int(best[full][last]))
    return Plan("optimal", tuple(order), tuple(completion), makespan, int(best[full][last]))


def _plan_within_cap(n, from_start, between, start_travel, travel, weight, cap):
    """The best order whose makespan is at most ``cap``, or None if there is none.

    The plain DP keeps one (least-cost) time per state, but under the paper objective a
    dearer partial order can finish sooner and be the only one within the cap. So
    states here are (done jobs, last job, step), steps bounded by the cap.
    """
    states: dict[tuple[int, int], dict[int, tuple[int, tuple | None]]] = {}
    for j in range(n):
        if from_start[j] <= cap:
            states.setdefault((1 << j, j), {})[from_start[j]] = (
                weight(0, from_start[j], start_travel[j]), None)
    for mask in range(1, 1 << n):
        for last in range(n):
            for t, (cost, _) in list(states.get((mask, last), {}).items()):
                for j in range(n):
                    if mask & (1 << j) or t + between[last][j] > cap:
                        continue
                    t2 = t + between[last][j]
                    c2 = cost + weight(mask, between[last][j], travel[last][j])
                    slot = states.setdefault((mask | (1 << j), j), {})
                    if t2 not in slot or c2 < slot[t2][0]:
                        slot[t2] = (c2, (mask, last, t))
    full = (1 << n) - 1
    finals = [(cost, t, last) for last in range(n)
              for t, (cost, _) in states.get((full, last), {}).items()]
    if not finals:
        return None
    cost, t, last = min(finals)
    order, key = [], (full, last, t)
    while key is not None:
        mask, j, step = key
        order.append(j)
        key = states[(mask, j)][step][1]
    return order[::-1], cost


@dataclass(frozen=True)
class JobLegs:
    """A robot's legs over a job list: steps to *finish* a job (travel to its pick,
    carry to its drop, its dwell), first from the start, then from finishing another.

    Attributes:
        from_start: ``from_start[j]``: steps from the start until job j is done.
        between: ``between[i][j]``: steps from finishing job i until job j is done.
        start_travel, travel: The same without the dwell (the part travelled, D in
            the objectives).
    """

    from_start: list[int]
    between: list[list[int]]
    start_travel: list[int]
    travel: list[list[int]]


def leg_lengths(world: GridWorld, start: Cell, jobs: list[Job]) -> JobLegs | None:
    """The legs of ``jobs`` for a robot at ``start``; None if a cell cannot be reached."""
    def dist(a: Cell, b: Cell) -> int | None:
        return world.distance(a, b) if world.is_free(a) and world.is_free(b) else None

    own = [dist(job.pick, job.drop) for job in jobs]
    to_pick = [[dist(a.drop, b.pick) for b in jobs] for a in jobs]
    first = [dist(start, job.pick) for job in jobs]
    if None in own or None in first or any(None in row for row in to_pick):
        return None
    n = range(len(jobs))
    start_travel = [first[j] + own[j] for j in n]
    travel = [[to_pick[i][j] + own[j] for j in n] for i in n]
    return JobLegs(from_start=[start_travel[j] + jobs[j].dwell for j in n],
                   between=[[travel[i][j] + jobs[j].dwell for j in n] for i in n],
                   start_travel=start_travel, travel=travel)


def _unwind(parent: list[list[int]], mask: int, last: int) -> list[int]:
    order = []
    while last != -1:
        order.append(last)
        mask, last = mask & ~(1 << last), parent[mask][last]
    return order[::-1]


def completion_times(order: Sequence[int], from_start: list[int],
                     between: list[list[int]]) -> list[int]:
    """When each job of ``order`` is done, by job index (0 for the jobs not in it), over
    a robot's legs (:class:`JobLegs`'s ``from_start`` and ``between``)."""
    done = [0] * len(from_start)
    t, prev = 0, None
    for j in order:
        t += from_start[j] if prev is None else between[prev][j]
        done[j], prev = t, j
    return done
