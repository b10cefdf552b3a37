"""The routing MILP both the event planner and the Oracle are built on."""

import itertools

import pytest

from ara.coordination import routing
from ara.coordination.milp import Solution
from ara.coordination.oracle import Schedule
from ara.coordination.planner_dp import Plan
from ara.coordination.planner_milp import EventPlan
from ara.coordination.status import STATUSES, WITH_SOLUTION
from ara.errors import ConfigError

# Two robots on a line at 0 and 10; stops at 2, 3 and 9. Legs are distances.
DEPOTS = {"r0": 0, "r1": 10}
STOPS = {"a": 2, "b": 3, "c": 9}


def line_problem(horizon=20):
    legs = [routing.Leg(d, s, abs(DEPOTS[d] - STOPS[s]), f"x[{d},{s}]", from_depot=True)
            for d in DEPOTS for s in STOPS]
    legs += [routing.Leg(i, j, abs(STOPS[i] - STOPS[j]), f"y[{i},{j}]")
             for i, j in itertools.permutations(STOPS, 2)]
    return routing.RoutingProblem(tuple(DEPOTS), tuple(STOPS), tuple(legs), horizon)


def test_least_travel_splits_the_stops_between_the_robots():
    """Tests build, solve and routes together: the cheapest routes (sum of legs) send
    r0 to a then b (2 + 1) and r1 to c (1), and the stops' times follow the legs."""
    problem = line_problem()
    model = routing.build(problem)
    for leg in problem.legs:
        model.add_cost(leg.arc, leg.steps)
    solution = routing.solve(model)
    assert solution.status == "optimal" and solution.objective == pytest.approx(4)
    assert routing.routes(problem, solution.values) == (("a", "b"), ("c",))
    assert solution.values["t[b]"] >= 3 - 1e-6 and solution.values["t[c]"] >= 1 - 1e-6


def test_the_horizon_bounds_every_stop_time():
    """Tests the horizon as a makespan cap: with 2 steps, stop b (3 from r0, 7 from r1)
    cannot be reached, and the solver says so instead of raising."""
    solution = routing.solve(routing.build(line_problem(horizon=2)))
    assert solution.status == "infeasible" and not solution.has_solution


def test_depots_may_stay_idle_unless_they_must_leave():
    """Tests ``depots_leave``: one stop and two robots is a plan with an idle robot,
    and no plan at all if every robot must take a stop."""
    legs = tuple(routing.Leg(d, "c", abs(x - STOPS["c"]), f"x[{d},c]", from_depot=True)
                 for d, x in DEPOTS.items())
    for leave, status, expected in ((False, "optimal", ((), ("c",))),
                                    (True, "infeasible", None)):
        problem = routing.RoutingProblem(tuple(DEPOTS), ("c",), legs, 20, depots_leave=leave)
        model = routing.build(problem)
        model.add_cost("t[c]", 1)
        solution = routing.solve(model)
        assert solution.status == status
        if expected:
            assert routing.routes(problem, solution.values) == expected


def test_legs_and_problems_check_themselves():
    with pytest.raises(ConfigError, match="steps must be >= 0"):
        routing.Leg("a", "b", -1, "x")
    with pytest.raises(ConfigError, match="not a depot or stop"):
        routing.RoutingProblem(("r0",), ("a",), (routing.Leg("r9", "a", 1, "x"),), 5)
    with pytest.raises(ConfigError, match="horizon must be >= 0"):
        routing.RoutingProblem(("r0",), (), (), -1)


def test_plans_schedules_and_solver_results_share_one_status_vocabulary():
    """Tests that each result type refuses a status outside the shared words, and that
    'has a plan' means the same for each."""
    assert set(WITH_SOLUTION) < set(STATUSES)
    for make in (lambda s: Solution(s), lambda s: Plan(s), lambda s: EventPlan(s),
                 lambda s: Schedule((), (), 0, 0, False, s)):
        with pytest.raises(ValueError, match="unknown status 'done'"):
            make("done")
    assert Solution("feasible").has_solution and not Solution("time_limit").has_solution
    assert Plan("optimal").feasible and not Plan("over_cap").feasible
    assert EventPlan("feasible").feasible and not EventPlan("unreachable").feasible
