"""Routes as a MILP: the ordering model the robot's planner and the fleet Oracle share.

Routes leave *depots* (robots' starts, step 0) and visit *stops* (a robot's events, or
the fleet's jobs), each stop exactly once:

- a binary per :class:`Leg` (``origin`` straight to ``stop``); every stop has one
  predecessor, every depot and stop at most one successor;
- ``u[s]``: the stop's position on its route (Miller-Tucker-Zemlin order, which also
  forbids cycles of zero-length legs, e.g. a pick and a place at the same cell);
- a time per stop, at least ``steps`` after its predecessor's along a chosen leg
  (waiting allowed), at most ``horizon``.

:func:`build` writes that into a :class:`~ara.coordination.milp.LinearModel`, to which
each caller adds its own part (the planner: STL windows, exclusions, its objective; the
Oracle: job costs, pins); :func:`solve` runs a solver; :func:`routes` reads the routes
back. The legs are the caller's: the planner's are BFS distances between event cells,
the Oracle's the per-robot job legs of :func:`~ara.coordination.planner_dp.leg_lengths`.
"""

from __future__ import annotations

from dataclasses import dataclass

from ara.coordination.milp import LinearModel, MILPSolver, Solution, make_solver
from ara.errors import ConfigError


@dataclass(frozen=True)
class Leg:
    """One move a route may make.

    Attributes:
        origin: A depot's name (``from_depot``) or a stop's.
        stop: The stop it reaches.
        steps: Least steps between leaving ``origin`` and doing ``stop`` (>= 0).
        arc: The name of the leg's binary in the model.
        from_depot: Whether ``origin`` is a depot (a route's first leg).
    """

    origin: str
    stop: str
    steps: int
    arc: str
    from_depot: bool = False

    def __post_init__(self) -> None:
        if self.steps < 0:
            raise ConfigError(f"leg {self.origin}->{self.stop}: steps must be >= 0, "
                              f"got {self.steps}")


@dataclass(frozen=True)
class RoutingProblem:
    """Depots, stops, the legs between them and the latest step.

    Attributes:
        depots: Where routes start, at step 0.
        stops: What the routes must visit, each once.
        legs: The moves allowed; the model's binaries are made in this order.
        horizon: Latest step of any stop (a makespan cap).
        time: Prefix of the stops' time variables (``t[s]``).
        depots_leave: Every depot's route takes at least one stop (a robot that must
            move); otherwise a depot may stay idle.
    """

    depots: tuple[str, ...]
    stops: tuple[str, ...]
    legs: tuple[Leg, ...]
    horizon: int
    time: str = "t"
    depots_leave: bool = False

    def __post_init__(self) -> None:
        if self.horizon < 0:
            raise ConfigError(f"horizon must be >= 0, got {self.horizon}")
        depots, stops = set(self.depots), set(self.stops)
        for leg in self.legs:
            if leg.stop not in stops or leg.origin not in (depots if leg.from_depot else stops):
                raise ConfigError(f"leg {leg.origin}->{leg.stop} names a node that is not "
                                  "a depot or stop of the problem")

    def time_of(self, stop: str) -> str:
        return f"{self.time}[{stop}]"


def build(problem: RoutingProblem, model: LinearModel | None = None) -> LinearModel:
    """The routing part of a model (into ``model``, or a new one), without an objective."""
    m = model if model is not None else LinearModel()
    p, n = problem, len(problem.stops)
    into = {s: [] for s in p.stops}
    for leg in p.legs:
        into[leg.stop].append(leg)
    for s in p.stops:  # no stop before a route can reach it: a bound the LP can use
        first = [leg.steps for leg in into[s] if leg.from_depot]
        m.var(p.time_of(s), min(first, default=0), p.horizon)
        m.var(f"u[{s}]", 1, n)
    for leg in p.legs:
        m.binary(leg.arc)
    for s in p.stops:
        m.eq({leg.arc: 1 for leg in into[s]}, 1)
    leaving: dict[tuple[bool, str], dict[str, float]] = {}
    for leg in p.legs:
        leaving.setdefault((leg.from_depot, leg.origin), {})[leg.arc] = 1
    for depot in p.depots:
        if (row := leaving.get((True, depot))):
            (m.eq if p.depots_leave else m.le)(row, 1)
    for s in p.stops:
        if (row := leaving.get((False, s))):
            m.le(row, 1)
    big = p.horizon + max((leg.steps for leg in p.legs), default=0) + 1
    for leg in p.legs:
        t = p.time_of(leg.stop)
        if leg.from_depot:  # the depot's time is 0
            m.ge({t: 1, leg.arc: -leg.steps}, 0)
            continue
        m.ge({t: 1, p.time_of(leg.origin): -1, leg.arc: -big}, leg.steps - big)
        m.ge({f"u[{leg.stop}]": 1, f"u[{leg.origin}]": -1, leg.arc: -n}, 1 - n)
    return m


def solve(model: LinearModel, solver: MILPSolver | None = None,
          time_limit_s: float = 10.0) -> Solution:
    """``model`` solved by ``solver`` (HiGHS by default); never raises on failure."""
    return (solver or make_solver()).solve(model, time_limit_s)


def routes(problem: RoutingProblem, values: dict[str, float]) -> tuple[tuple[str, ...], ...]:
    """Each depot's stops in the order visited, read from a solution's chosen legs."""
    after: dict[tuple[bool, str], str] = {}
    for leg in problem.legs:
        if values.get(leg.arc, 0.0) > 0.5:
            after[leg.from_depot, leg.origin] = leg.stop
    out = []
    for depot in problem.depots:
        route, stop = [], after.get((True, depot))
        while stop is not None and len(route) < len(problem.stops):
            route.append(stop)
            stop = after.get((False, stop))
        out.append(tuple(route))
    return tuple(out)
