"""The event MILP against the exact DP, and on specs the DP cannot express."""

import random

import pytest

from ara.coordination.events import UnsupportedSpec, Vocabulary, compile_spec
from ara.coordination.milp import HiGHSSolver, LinearModel, make_solver
from ara.coordination.planner_dp import Job, plan_jobs
from ara.coordination.planner_milp import plan_spec
from ara.coordination.specs import jobs_spec, jobs_vocabulary
from ara.coordination.world import GridWorld
from ara.errors import ConfigError
from ara.grammars import parse

PAPER = GridWorld.paper()
# The right column is walled off: cells there cannot be reached from the left.
WALLED = GridWorld.from_text("....#.\n....#.\n....#.\n....#.\n")


def milp_plan(world, start, jobs, objective="makespan", cap=None):
    return plan_spec(world, start, {"own": jobs_spec(jobs)}, jobs_vocabulary(world, jobs),
                     objective, cap)


def random_instance(rng, world, max_jobs=4, dwell=False):
    cells = world.free_cells
    jobs = []
    for _ in range(rng.randint(0, max_jobs)):
        pick = rng.choice(cells)
        drop = pick if rng.random() < 0.2 else rng.choice(cells)  # pick == drop happens
        jobs.append(Job(pick, drop, dwell=rng.choice([0, 2]) if dwell else 0))
    return rng.choice(cells), jobs


@pytest.mark.parametrize("objective", ["makespan", "authors"])
def test_milp_optimum_equals_the_dp_on_random_instances(objective):
    """Tests 60 instances per objective on the paper's grid and a walled one: no jobs
    (an idle helper), pick == drop, unreachable cells and a cap the best plan exceeds.
    The statuses must agree, and the optimum and its makespan too."""
    rng = random.Random(objective)
    seen = set()
    for k in range(60):
        world = WALLED if k % 4 == 3 else PAPER
        start, jobs = random_instance(rng, world, dwell=True)
        cap = rng.choice([None, 12, 30])
        dp = plan_jobs(world, start, jobs, objective, cap=cap)
        mp = milp_plan(world, start, jobs, objective, cap)
        seen.add(dp.status)
        expected = {"optimal": "optimal", "over_cap": "infeasible",
                    "unreachable": "unreachable"}[dp.status]
        assert mp.status == expected, (start, jobs, cap)
        if dp.feasible:
            assert (mp.objective, mp.makespan) == (dp.objective, dp.makespan)
            assert len(mp.order) == 2 * len(jobs)
    assert seen == {"optimal", "over_cap", "unreachable"}


def test_paper_objective_weighs_the_help_group():
    """D + T(help) + M: with the help job's events as their own group, the MILP matches
    the DP's 2M + t_help and reports when the help job is done."""
    from ara.coordination.protocol import Helper, HelpRequest, make_offer, request_text

    rng = random.Random(7)
    for _ in range(20):
        start, jobs = random_instance(rng, PAPER, max_jobs=3)
        site = rng.choice(PAPER.free_cells)
        request = HelpRequest("r", site, ("navigate",), request_text(site, ("navigate",)))
        helper = Helper(0, start, tuple(jobs))
        dp, mp = (make_offer(PAPER, helper, request, planner=p) for p in ("dp", "milp"))
        assert (dp.can_help, dp.tau_help, dp.tau_new) == (mp.can_help, mp.tau_help, mp.tau_new)


def test_time_windows_and_nested_until():
    """F[a,b] bounds an event's step; waiting is allowed; a window nobody can meet
    makes the plan infeasible, not a crash."""
    vocab = Vocabulary({"a": (0, 7), "b": (7, 7)})
    plan = plan_spec(PAPER, (0, 0), {"t": parse("F[10,20] a & F b")}, vocab)
    assert plan.status == "optimal" and plan.times["a"] == 10 and plan.makespan == 17
    late = plan_spec(PAPER, (0, 0), {"t": parse("F[0,3] a")}, vocab)
    assert late.status == "infeasible"
    seq = plan_spec(PAPER, (0, 0), {"t": parse("!a U (b & F[0,50] a)")}, vocab)
    assert seq.order == ("b", "a") and seq.times == {"b": 14, "a": 21}


def test_keep_out_regions_lengthen_paths():
    """G !region removes the region's cells from every path."""
    vocab = Vocabulary({"goal": (0, 2)}, regions={"hall": frozenset({(0, 1)})})
    free = plan_spec(PAPER, (0, 0), {"t": parse("F goal")}, vocab)
    around = plan_spec(PAPER, (0, 0), {"t": parse("F goal & G !hall")}, vocab)
    assert free.makespan == 2 and around.makespan == 8  # down column 0, along row 3, up


@pytest.mark.parametrize(("flat", "nested"), [
    ("F(a & F b & c)", "F((a & F b) & c)"),
    ("F a & G(!hall & ok)", "F a & G((!hall & ok) & ok)"),
    ("F a & F b & G !hall", "(F a & F b) & G !hall"),
])
def test_bracketing_of_a_conjunction_changes_no_plan(flat, nested):
    """The grammar writes two operands to an &, so a model answers ``(x & y) & z`` as
    often as ``x & y & z``: both are the same program."""
    vocab = Vocabulary({"a": (0, 2), "b": (7, 7), "c": (0, 2)},
                       regions={"hall": frozenset({(0, 1)})}, invariants=frozenset({"ok"}))
    programs = [compile_spec({"t": parse(text)}, vocab) for text in (flat, nested)]
    assert programs[0] == programs[1] and programs[0].events


def test_formulas_outside_the_event_fragment_are_refused_by_name():
    vocab = Vocabulary({"a": (0, 0), "b": (7, 7)})
    for text in ("F a | F b", "G[0,5] !a", "!a"):
        with pytest.raises(UnsupportedSpec, match="cannot plan for|names no event"):
            plan_spec(PAPER, (0, 0), {"t": parse(text)}, vocab)
    with pytest.raises(UnsupportedSpec, match="names no event"):
        plan_spec(PAPER, (0, 0), {"t": parse("F c")}, vocab)
    with pytest.raises(ConfigError, match="objective must be one of"):
        plan_spec(PAPER, (0, 0), {"t": parse("F a")}, vocab, objective="fastest")


def test_a_highs_solve_writes_nothing_to_stdout(capfd):
    """`ara coord plan --json` prints the plan on stdout; HiGHS 1.16 prints a banner from C++
    when it is constructed, which would break every JSON reader."""
    m = LinearModel()
    m.binary("x")
    m.ge({"x": 1}, 1)
    assert HiGHSSolver().solve(m).status == "optimal"
    assert capfd.readouterr().out == ""


def test_solver_reports_infeasible_models_and_unknown_solvers():
    m = LinearModel()
    m.binary("x")
    m.ge({"x": 1}, 2)
    assert HiGHSSolver().solve(m).status == "infeasible"
    with pytest.raises(ConfigError, match="unknown solver"):
        make_solver("cplex")


def test_gurobi_backend_finds_the_same_optima():
    """Tests Gurobi (installed by setup; the wheel's bundled license covers these
    models, a few hundred variables) against HiGHS on the Oracle and the planner."""
    from ara.coordination.milp import GurobiSolver
    from ara.coordination.oracle import Fleet, exact
    from ara.coordination.trials import make_trial

    trial = make_trial(0, 3000)
    fleet = Fleet(PAPER, trial.starts, (*trial.jobs, trial.help_job), help_job=12)
    assert exact(fleet, GurobiSolver()).cost == exact(fleet, HiGHSSolver()).cost
    # Trial 9 has several optimal 12-job schedules, and the two solvers' first answers
    # differ; the canonical second solve makes them the same schedule.
    trial = make_trial(9, 3009)
    fleet = Fleet(PAPER, trial.starts, trial.jobs, cap=50)
    firsts = [exact(fleet, s(), canonical=False).routes for s in (GurobiSolver, HiGHSSolver)]
    assert firsts[0] != firsts[1]
    assert exact(fleet, GurobiSolver()).routes == exact(fleet, HiGHSSolver()).routes
    rng = random.Random(3)
    for _ in range(5):
        start, jobs = random_instance(rng, PAPER)
        spec, vocab = {"own": jobs_spec(jobs)}, jobs_vocabulary(PAPER, jobs)
        a = plan_spec(PAPER, start, spec, vocab, "authors", solver=GurobiSolver())
        b = plan_spec(PAPER, start, spec, vocab, "authors", solver=HiGHSSolver())
        assert (a.status, a.objective, a.makespan) == (b.status, b.objective, b.makespan)


def test_a_model_beyond_the_gurobi_pip_license_is_a_clear_error():
    """Tests that 2,001 variables, one more than the wheel's license allows, stop with
    an error that names the limit and the way out, not a silent failed solve."""
    from ara.coordination.milp import GurobiSolver, LinearModel, SolverLicenseError

    model = LinearModel()
    names = [model.binary(f"x{i}", cost=1.0) for i in range(2001)]
    model.row({name: 1.0 for name in names}, lo=3)
    with pytest.raises(SolverLicenseError, match="2001 variables.*--solver highs"):
        GurobiSolver().solve(model)
    assert HiGHSSolver().solve(model).objective == 3
