"""The event-based MILP: an event program + a grid -> a robot's optimal plan.

Nodes are the start and the required events; travel times are BFS distances between
their cells (without the cells the spec keeps out of) plus each event's dwell. The
ordering part is :mod:`ara.coordination.routing`'s, with the start as the one depot:

- ``x[i,j]`` (binary): event j comes right after node i, one path from the start;
- ``u[j]``: position in the path; ``t[j]``: the step event j happens;

and the spec adds:

- windows bound ``t[event] - t[anchor]`` and order the event after the anchor;
  "no y between a and b" is a disjunction (y before a, or after b) with one binary.

Objectives (Sec. IV of the paper; D = legs travelled, M = makespan):
``makespan`` M; ``paper`` D + T(help) + M; ``authors`` M + D. Binaries are per pair of
events, not per cell and step as in the authors' grid x time model, and the tests hold
every optimum against the DP's.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ara.coordination import routing
from ara.coordination.events import START, EventProgram, Vocabulary, compile_spec
from ara.coordination.milp import MILPSolver
from ara.coordination.planner_dp import OBJECTIVES
from ara.coordination.status import WITH_SOLUTION, Status, checked
from ara.coordination.world import Cell, GridWorld
from ara.errors import ConfigError
from ara.grammars import Formula


@dataclass(frozen=True)
class EventPlan:
    """A robot's plan from the MILP, or why there is none.

    Attributes:
        status: ``optimal``; ``feasible`` (time limit, not proven); ``unreachable``;
            ``infeasible`` (no plan satisfies the spec within the cap); ``time_limit``;
            ``error``.
        order: Events in the order done.
        times: Step of each event.
        makespan: Step of the last event.
        objective: The objective's value.
        help_time: Step by which the ``help`` group's events are all done (if any).
        solve_s: Solver wall time; ``gap``: its relative MIP gap; ``size``: model size.
    """

    status: Status
    order: tuple[str, ...] = ()
    times: dict[str, int] = field(default_factory=dict)
    makespan: int = 0
    objective: float = 0.0
    help_time: int | None = None
    solve_s: float = 0.0
    gap: float | None = None
    size: dict[str, int] = field(default_factory=dict)

    def __post_init__(self) -> None:
        checked(self.status)

    @property
    def feasible(self) -> bool:
        return self.status in WITH_SOLUTION


def plan_spec(world: GridWorld, start: Cell, conjuncts: dict[str, Formula],
              vocab: Vocabulary, objective: str = "makespan", cap: int | None = None,
              solver: MILPSolver | None = None, time_limit_s: float = 10.0) -> EventPlan:
    """Compile the spec and solve for the best plan of a robot at ``start``.

    Args:
        conjuncts: Named parts of the spec; a part named ``help`` is the one whose
            completion time the ``paper`` objective weighs.
        vocab: What the propositions mean.
        objective: ``makespan``, ``paper`` or ``authors``.
        cap: Largest allowed makespan.

    Raises:
        UnsupportedSpec: The spec is outside the event fragment.
        WorldError: The start or a cell the spec must visit is not free.
    """
    if objective not in OBJECTIVES:
        raise ConfigError(f"objective must be one of {OBJECTIVES}, got {objective!r}")
    program = compile_spec(conjuncts, vocab)
    return solve_program(world, start, program, vocab, objective, cap, solver, time_limit_s)


def solve_program(world: GridWorld, start: Cell, program: EventProgram, vocab: Vocabulary,
                  objective: str = "makespan", cap: int | None = None,
                  solver: MILPSolver | None = None, time_limit_s: float = 10.0) -> EventPlan:
    events = program.events
    world.require_free(start, "the start")
    for e in events:
        world.require_free(vocab.events[e], f"event {e!r} at")
    if not events:
        return EventPlan("optimal", help_time=0 if "help" in program.groups else None)
    cells = {START: start, **{e: vocab.events[e] for e in events}}
    weights = _leg_weights(world, cells, program.avoid, vocab)
    if weights is None:
        return EventPlan("unreachable")
    problem, model, scale = _build(program, weights, objective, cap)
    solution = routing.solve(model, solver, time_limit_s)
    if not solution.has_solution:
        return EventPlan(solution.status, solve_s=solution.solve_s, size=model.size)
    v = solution.values
    (order,) = routing.routes(problem, v)
    times = _earliest_times(order, weights, program) or {e: round(v[f"t[{e}]"]) for e in events}
    help_events = program.groups.get("help", set())
    help_time = max((times[e] for e in help_events), default=0) if "help" in program.groups \
        else None
    makespan = max(times.values())
    total = round(solution.objective or 0.0)
    value = total if scale == 1 else (total - makespan) // scale
    return EventPlan(solution.status, order, times, makespan, value, help_time,
                     solution.solve_s, solution.gap, model.size)


def _earliest_times(order: tuple[str, ...], weights: dict,
                    program: EventProgram) -> dict[str, int] | None:
    """Each event as early as the order allows (the solver only bounds times from
    below, so its values may idle where nothing is weighed); None if that breaks a
    window's upper bound, in which case the solver's own times stand."""
    times: dict[str, int] = {START: 0}
    prev = START
    for e in order:
        t = times[prev] + weights[prev, e][1]
        for w in program.windows:
            if w.event == e:
                t = max(t, times[w.anchor] + w.lo)
        times[e], prev = t, e
    for w in program.windows:
        if w.hi is not None and times[w.event] - times[w.anchor] > w.hi:
            return None
    del times[START]
    return times


def _leg_weights(world: GridWorld, cells: dict[str, Cell], avoid: set[Cell],
                 vocab: Vocabulary) -> dict[tuple[str, str], tuple[int, int]] | None:
    """(distance, distance + dwell of the target) for every ordered pair of nodes."""
    graph = world if not avoid else GridWorld(world.rows, world.cols,
                                              world.obstacles | frozenset(avoid - {cells[START]}))
    if any(not graph.is_free(c) for c in cells.values()):
        return None
    out = {}
    for i, ci in cells.items():
        dist = graph.distances_from(ci)
        for j, cj in cells.items():
            if j == START or i == j:
                continue
            if cj not in dist:
                if i == START:
                    return None
                continue
            out[i, j] = (dist[cj], dist[cj] + vocab.dwell.get(j, 0))
    return out


def _build(program: EventProgram, weights: dict, objective: str, cap: int | None):
    events = program.events
    n = len(events)
    finite_his = [w.hi for w in program.windows if w.hi is not None]
    longest = max(w for _, w in weights.values())
    horizon = n * longest + max([w.lo for w in program.windows] + [0]) * n + 1
    if finite_his:
        horizon += max(finite_his)
    if cap is not None:
        horizon = min(horizon, cap)
    problem = routing.RoutingProblem(
        (START,), tuple(events),
        tuple(routing.Leg(i, j, w, f"x[{i},{j}]", from_depot=i == START)
              for (i, j), (_, w) in weights.items()),
        horizon, depots_leave=True)
    m = routing.build(problem)
    m.var("M", 0, horizon)
    for e in events:
        m.ge({"M": 1, f"t[{e}]": -1}, 0)
    for w in program.windows:  # the start is step 0, before everything
        after_anchor = {} if w.anchor == START else {f"t[{w.anchor}]": -1}
        m.row({f"t[{w.event}]": 1, **after_anchor}, w.lo,
              w.hi if w.hi is not None else float("inf"))
        if w.anchor != START:
            m.ge({f"u[{w.event}]": 1, f"u[{w.anchor}]": -1}, 1)
    adjacent = set(_adjacent_pairs(program))
    for anchor, until in adjacent:
        if (anchor, until) in weights:
            m.lower[m.index[f"x[{anchor},{until}]"]] = 1.0
    for k, ex in enumerate(program.exclusions):
        if ex.event not in events or ex.event in (ex.anchor, ex.until):
            continue  # an event never done is never in between
        if (ex.anchor, ex.until) in adjacent:
            continue  # the fixed leg already leaves no room between
        if ex.anchor == START:
            m.ge({f"u[{ex.event}]": 1, f"u[{ex.until}]": -1}, 1)
            continue
        z = m.binary(f"z[{k}]")  # 1: after `until`; 0: before `anchor`
        m.le({f"u[{ex.event}]": 1, f"u[{ex.anchor}]": -1, z: -n}, -1)
        m.ge({f"u[{ex.event}]": 1, f"u[{ex.until}]": -1, z: -n}, 1 - n)
    # Lexicographic: the objective, then the makespan (as the DP breaks ties), with
    # weight `scale` > any makespan so the second never trades against the first.
    scale = 1 if objective == "makespan" else horizon + 1
    m.add_cost("M", 1 + (scale if objective != "makespan" else 0))
    if objective != "makespan":
        for (i, j), (d, _) in weights.items():
            m.add_cost(f"x[{i},{j}]", scale * d)
        if objective == "paper" and program.groups.get("help"):
            m.var("T_help", 0, horizon, cost=scale)
            for e in program.groups["help"]:
                m.ge({"T_help": 1, f"t[{e}]": -1}, 0)
    return problem, m, scale


def _adjacent_pairs(program: EventProgram) -> list[tuple[str, str]]:
    """(a, b) such that b follows a with every other event excluded in between.

    The PNP spec's single-carry part says exactly this for each job: the place comes
    right after its pick. Fixing that leg instead of one disjunction per other event
    turns the model into a small routing problem over jobs, which is what keeps HiGHS
    in milliseconds.
    """
    blocked: dict[tuple[str, str], set[str]] = {}
    for ex in program.exclusions:
        if ex.anchor != START:
            blocked.setdefault((ex.anchor, ex.until), set()).add(ex.event)
    ordered = {(w.anchor, w.event) for w in program.windows}
    events = set(program.events)
    return [(a, b) for (a, b), ys in blocked.items()
            if (a, b) in ordered and a in events and b in events and events - {a, b} <= ys]
