"""The centralized Oracle: all jobs over all robots, with full knowledge.

The problem (the paper's B1): robots at distinct starts, pick-and-place jobs each done
in one go (pick, carry, place), open routes, a makespan cap per robot. The cost is
``J = sum of makespans + the requester's wait`` (the completion time of the help job,
when there is one). Two solvers:

- :func:`ils`: the paper's appendix, GreedyInsertion then iterated local search
  (perturb, local search, accept if better or with probability exp(-(J'-J)/T), keep
  the best);
- :func:`exact`: a MILP over job successions (HiGHS by default) that proves the
  optimum, the physical limit the ILS is measured against. ``pinned`` fixes jobs to
  robots (baseline B3).
"""

from __future__ import annotations

import math
import random
import time
from collections.abc import Sequence
from dataclasses import dataclass, replace
from functools import cached_property

from ara.coordination import routing
from ara.coordination.milp import LinearModel, MILPSolver, make_solver
from ara.coordination.planner_dp import Job, completion_times, leg_lengths
from ara.coordination.status import Status, checked
from ara.coordination.world import Cell, GridWorld
from ara.errors import AraError, ConfigError

OVER_CAP_PENALTY = 1000


class FleetError(AraError, ValueError):
    """A fleet problem with cells that are not free or jobs no robot can reach."""


@dataclass(frozen=True)
class Fleet:
    """Robots, jobs, and which job (if any) someone is waiting for.

    Args:
        world: The grid.
        starts: Each robot's cell.
        jobs: All jobs.
        help_job: Index of the help job in ``jobs``; its completion time is added to J.
        cap: Largest makespan allowed per robot.
    """

    world: GridWorld
    starts: tuple[Cell, ...]
    jobs: tuple[Job, ...]
    help_job: int | None = None
    cap: int | None = 50

    def __post_init__(self) -> None:
        if not self.starts:
            raise FleetError("a fleet needs at least one robot: give each robot's start cell")
        for k, start in enumerate(self.starts):
            self.world.require_free(start, f"robot {k}'s start")
        if self.help_job is not None and not 0 <= self.help_job < len(self.jobs):
            raise FleetError(f"help_job {self.help_job} is not a job index "
                             f"(0..{len(self.jobs) - 1})")
        if self.cap is not None and self.cap < 0:
            raise FleetError(f"cap must be >= 0 or None, got {self.cap}")

    @cached_property
    def legs(self) -> tuple[list[list[int]], list[list[int]]]:
        """``first[k][j]``: robot k's steps to finish job j first; ``then[i][j]``:
        steps to finish j right after i (the per-robot planner's legs)."""
        first = []
        for k, start in enumerate(self.starts):
            legs = leg_lengths(self.world, start, list(self.jobs))
            if legs is None:
                raise FleetError(f"no path from robot {k}'s start {start} to every job cell, "
                                 "or from one job to another")
            first.append(legs.from_start)
        return first, legs.between


@dataclass(frozen=True)
class Schedule:
    """Each robot's jobs in order, and what they cost."""

    routes: tuple[tuple[int, ...], ...]
    makespans: tuple[int, ...]
    help_time: int
    cost: int  # sum of makespans + help_time
    feasible: bool  # a schedule, every makespan within the cap
    status: Status = "heuristic"
    solve_s: float = 0.0

    def __post_init__(self) -> None:
        checked(self.status)


def _walk(fleet: Fleet, k: int, route: Sequence[int]) -> tuple[int, int]:
    """Robot k's makespan on ``route``, and when it finishes the help job (0 if not on it)."""
    first, then = fleet.legs
    done = completion_times(route, first[k], then)
    help_done = done[fleet.help_job] if fleet.help_job in route else 0
    return (done[route[-1]] if route else 0), help_done


def evaluate(fleet: Fleet, routes: Sequence[Sequence[int]], status: str = "heuristic",
             solve_s: float = 0.0) -> Schedule:
    walks = [_walk(fleet, k, route) for k, route in enumerate(routes)]
    makespans = [t for t, _ in walks]
    help_time = sum(wait for _, wait in walks)  # at most one route holds the help job
    feasible = fleet.cap is None or max(makespans, default=0) <= fleet.cap
    return Schedule(tuple(tuple(r) for r in routes), tuple(makespans), help_time,
                    sum(makespans) + help_time, feasible, status, solve_s)


def _route_cost(fleet: Fleet, k: int, route: Sequence[int]) -> float:
    """Robot k's makespan + the help wait if it carries the help job, + cap penalty."""
    t, wait = _walk(fleet, k, route)
    over = max(0, t - fleet.cap) if fleet.cap is not None else 0
    return t + wait + OVER_CAP_PENALTY * over


def _penalized(fleet: Fleet, routes) -> float:
    return sum(_route_cost(fleet, k, r) for k, r in enumerate(routes))


def greedy_insertion(fleet: Fleet, order: Sequence[int] | None = None) -> list[list[int]]:
    """Insert jobs one by one where they raise the (penalized) cost least."""
    routes: list[list[int]] = [[] for _ in fleet.starts]
    costs = [_route_cost(fleet, k, r) for k, r in enumerate(routes)]
    for j in order if order is not None else range(len(fleet.jobs)):
        best = None
        for k in range(len(routes)):  # an insertion changes one route: cost only that one
            for pos in range(len(routes[k]) + 1):
                rise = _route_cost(fleet, k, routes[k][:pos] + [j] + routes[k][pos:]) - costs[k]
                if best is None or rise < best[0]:
                    best = (rise, k, pos)
        _, k, pos = best
        routes[k].insert(pos, j)
        costs[k] = _route_cost(fleet, k, routes[k])
    return routes


@dataclass(frozen=True)
class ILSSettings:
    """The iterated local search's knobs.

    Args:
        iterations: Perturb + local-search rounds.
        perturb_moves: Random relocations per perturbation.
        temperature: T in the acceptance probability exp(-(J' - J) / T) for worse J';
            0 accepts improvements only.
        seed: For the perturbations and the acceptance draws.
    """

    iterations: int = 100
    perturb_moves: int = 2
    temperature: float = 1.0
    seed: int = 0

    def __post_init__(self) -> None:
        if self.iterations < 0 or self.perturb_moves < 1 or not self.temperature >= 0:
            raise ConfigError(
                f"ILS needs iterations >= 0, perturb_moves >= 1 and temperature >= 0 (0: "
                f"accept improvements only); got {self.iterations}, {self.perturb_moves}, "
                f"{self.temperature}")


def _moves(routes: list[list[int]], pinned: dict[int, int]):
    """Every relocation (a job to any position of any robot) and swap of two jobs, as
    ``{robot: its new route}`` for the one or two robots a move changes."""
    where = [(k, p) for k, r in enumerate(routes) for p in range(len(r))]
    for k, p in where:
        j = routes[k][p]
        rest = routes[k][:p] + routes[k][p + 1:]
        for k2 in range(len(routes)):
            if j in pinned and pinned[j] != k2:
                continue
            target = rest if k2 == k else routes[k2]
            for p2 in range(len(target) + 1):
                if k2 == k and p2 == p:
                    continue
                moved = target[:p2] + [j] + target[p2:]
                yield {k: moved} if k2 == k else {k: rest, k2: moved}
    for a in range(len(where)):
        for b in range(a + 1, len(where)):
            (ka, pa), (kb, pb) = where[a], where[b]
            ja, jb = routes[ka][pa], routes[kb][pb]
            if ka != kb and ((ja in pinned and pinned[ja] != kb)
                             or (jb in pinned and pinned[jb] != ka)):
                continue
            if ka == kb:
                r = routes[ka][:]
                r[pa], r[pb] = jb, ja
                yield {ka: r}
            else:
                ra, rb = routes[ka][:], routes[kb][:]
                ra[pa], rb[pb] = jb, ja
                yield {ka: ra, kb: rb}


def local_search(fleet: Fleet, routes: list[list[int]],
                 pinned: dict[int, int] | None = None) -> list[list[int]]:
    """Best-improvement relocate/swap until no move lowers the cost.

    A move changes one or two routes, so only those are costed again.
    """
    pinned = pinned or {}
    routes = [r[:] for r in routes]
    costs = [_route_cost(fleet, k, r) for k, r in enumerate(routes)]
    while True:
        best, best_gain = None, 0.0
        for move in _moves(routes, pinned):
            gain = sum(costs[k] - _route_cost(fleet, k, r) for k, r in move.items())
            if gain > best_gain + 1e-9:
                best, best_gain = move, gain
        if best is None:
            return routes
        for k, r in best.items():
            routes[k], costs[k] = r, _route_cost(fleet, k, r)


def ils(fleet: Fleet, settings: ILSSettings = ILSSettings(),
        pinned: dict[int, int] | None = None) -> Schedule:
    """The paper's Oracle: GreedyInsertion, then iterated local search."""
    started = time.perf_counter()
    pinned = pinned or {}
    rng = random.Random(settings.seed)
    routes = greedy_insertion(fleet)
    for j, k in pinned.items():  # honour pins before searching
        for r in routes:
            if j in r:
                r.remove(j)
        routes[k].append(j)
    current = local_search(fleet, routes, pinned)
    cur_cost = _penalized(fleet, current)
    best, best_cost = current, cur_cost
    for _ in range(settings.iterations):
        cand = _perturb(current, rng, settings.perturb_moves, pinned)
        cand = local_search(fleet, cand, pinned)
        c = _penalized(fleet, cand)
        if c < cur_cost or (settings.temperature > 0 and
                            rng.random() < math.exp(-(c - cur_cost) / settings.temperature)):
            current, cur_cost = cand, c
        if c < best_cost:
            best, best_cost = cand, c
    return evaluate(fleet, best, "heuristic", time.perf_counter() - started)


def _perturb(routes: list[list[int]], rng: random.Random, moves: int,
             pinned: dict[int, int]) -> list[list[int]]:
    new = [r[:] for r in routes]
    for _ in range(moves):
        jobs = [j for r in new for j in r if j not in pinned]
        if not jobs:
            break
        j = rng.choice(jobs)
        for r in new:
            if j in r:
                r.remove(j)
        k = rng.randrange(len(new))
        new[k].insert(rng.randint(0, len(new[k])), j)
    return new


def exact(fleet: Fleet, solver: MILPSolver | None = None, pinned: dict[int, int] | None = None,
          time_limit_s: float = 60.0, canonical: bool = True) -> Schedule:
    """The optimum by MILP: job successions, completion times, MTZ order.

    ``x[k,j]``: robot k does j first; ``y[i,j]``: j right after i. Every job has one
    predecessor; each robot and job at most one successor. ``c[j] >= c[i] + leg`` on
    chosen successions bounds completion times (the cap bounds them all); the sum of
    chosen legs is the sum of makespans, and ``c[help]`` the requester's wait.

    An instance often has several optimal schedules, and solvers return different ones;
    the decentralized methods then start from different plans. With ``canonical`` a
    second solve keeps the optimum and picks, among the optimal schedules, the one of
    least fixed pseudo-random arc weights, so that HiGHS and Gurobi return the same
    schedule (checked on the paper's instances).
    """
    first, then = fleet.legs
    n, robots = len(fleet.jobs), len(fleet.starts)
    if n == 0:
        return evaluate(fleet, [[] for _ in fleet.starts], "optimal")
    pinned = pinned or {}
    horizon = fleet.cap if fleet.cap is not None else sum(
        max(max(first[k][j] for k in range(robots)), max(then[i][j] for i in range(n)))
        for j in range(n))
    problem = _routing_problem(fleet, pinned, horizon)
    m = routing.build(problem)
    for leg in problem.legs:  # the sum of chosen legs is the sum of makespans
        m.add_cost(leg.arc, leg.steps)
    if fleet.help_job is not None:
        m.add_cost(f"c[{fleet.help_job}]", 1)
    if pinned:  # r[j]: the robot doing job j, equal along a route
        for j in range(n):
            m.var(f"r[{j}]", 0, robots - 1)
        for leg in problem.legs:
            r, x = f"r[{leg.stop}]", leg.arc
            if leg.from_depot:
                k = int(leg.origin)
                m.le({r: 1, x: robots}, k + robots)
                m.ge({r: 1, x: -robots}, k - robots)
            else:
                m.le({r: 1, f"r[{leg.origin}]": -1, x: robots}, robots)
                m.ge({r: 1, f"r[{leg.origin}]": -1, x: -robots}, -robots)
        for j, k in pinned.items():
            m.row({f"r[{j}]": 1}, k, k)
    solver = solver or make_solver()
    solution = routing.solve(m, solver, time_limit_s)
    if not solution.has_solution:
        return Schedule((), (), 0, 0, False, solution.status, solution.solve_s)
    if canonical and solution.status == "optimal":
        solution = _canonical(m, solution, solver, time_limit_s)
    routes = [[int(j) for j in route] for route in routing.routes(problem, solution.values)]
    return evaluate(fleet, routes, solution.status, solution.solve_s)


def _routing_problem(fleet: Fleet, pinned: dict[int, int], horizon: int):
    """Robots as depots, jobs as stops: ``x[k,j]`` robot k does j first, ``y[i,j]`` j
    right after i, ``c[j]`` the step job j is done."""
    first, then = fleet.legs
    n, robots = len(fleet.jobs), len(fleet.starts)
    legs = [routing.Leg(str(k), str(j), first[k][j], f"x[{k},{j}]", from_depot=True)
            for k in range(robots) for j in range(n) if pinned.get(j, k) == k]
    legs += [routing.Leg(str(i), str(j), then[i][j], f"y[{i},{j}]")
             for i in range(n) for j in range(n) if i != j]
    return routing.RoutingProblem(tuple(map(str, range(robots))), tuple(map(str, range(n))),
                                  tuple(legs), horizon, time="c")


def _canonical(m: LinearModel, first, solver: MILPSolver, time_limit_s: float):
    """The optimal schedule of least fixed arc weights (seeded, 1..999 per successor
    arc); ``first`` where the second solve does not prove its optimum."""
    objective = {i: c for i, c in enumerate(m.cost) if c}
    # Costs are integers (legs and waits), so the optimum is a bound with no tolerance
    m.le({m.names[i]: c for i, c in objective.items()}, round(first.objective))
    weights = random.Random(0)
    m.cost = [0.0] * len(m.names)
    for i, name in enumerate(m.names):
        if name.startswith(("x[", "y[")):
            m.cost[i] = float(weights.randint(1, 999))
    second = solver.solve(m, time_limit_s)
    if second.status != "optimal":
        return first
    return replace(second, objective=first.objective, solve_s=first.solve_s + second.solve_s)
