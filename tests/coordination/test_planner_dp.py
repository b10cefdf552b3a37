"""The exact DP planner against brute force over every job order."""

import itertools
import random

import pytest

from ara.coordination.planner_dp import Job, plan_jobs
from ara.coordination.world import GridWorld
from ara.errors import ConfigError

WORLD = GridWorld.paper()


def brute_force(start, jobs, objective, help_index=None, cap=None):
    """Least objective over all orders (within ``cap``, if given), straight from the
    definitions; None if no order fits."""
    best = None
    for order in itertools.permutations(range(len(jobs))):
        t, moved, here, done = 0, 0, start, {}
        for j in order:
            legs = WORLD.distance(here, jobs[j].pick) + WORLD.distance(jobs[j].pick, jobs[j].drop)
            t, moved = t + legs + jobs[j].dwell, moved + legs
            here, done[j] = jobs[j].drop, t
        value = {"makespan": t, "authors": t + moved,
                 "paper": t + moved + (done[help_index] if help_index is not None else 0)}[
            objective]
        if cap is not None and t > cap:
            continue
        best = value if best is None else min(best, value)
    return best


def random_jobs(rng, n):
    cells = WORLD.free_cells
    return [Job(rng.choice(cells), rng.choice(cells), dwell=rng.choice([0, 0, 2]))
            for _ in range(n)]


@pytest.mark.parametrize("objective", ["makespan", "paper", "authors"])
def test_dp_equals_brute_force_on_random_instances(objective):
    """Tests 60 random instances of 1-5 jobs (pick may equal drop) per objective."""
    rng = random.Random(objective)
    for _ in range(60):
        jobs = random_jobs(rng, rng.randint(1, 5))
        start = rng.choice(WORLD.free_cells)
        help_index = rng.randrange(len(jobs)) if objective == "paper" else None
        plan = plan_jobs(WORLD, start, jobs, objective, help_index)
        assert plan.feasible
        assert plan.objective == brute_force(start, jobs, objective, help_index)
        assert sorted(plan.order) == list(range(len(jobs)))
        assert plan.makespan == max(plan.completion)


def test_paper_objective_does_the_help_job_early():
    """Tests that weighting the help job's completion changes the order: in a corridor,
    job first ends at step 7 with help at 7 (2*7+7 = 21); help first ends at 8 with help
    at 3 (2*8+3 = 19)."""
    corridor = GridWorld.from_text(".......")
    jobs = [Job((0, 5), (0, 5)), Job((0, 0), (0, 0), name="help")]
    by_makespan = plan_jobs(corridor, (0, 3), jobs, "makespan")
    by_paper = plan_jobs(corridor, (0, 3), jobs, "paper", help_index=1)
    assert by_makespan.order == (0, 1) and by_makespan.makespan == 7
    assert by_paper.order == (1, 0) and by_paper.objective == 19


def test_idle_robot_unreachable_cells_and_the_cap():
    """Tests no jobs, a job behind a wall, and a makespan over the cap."""
    assert plan_jobs(WORLD, (0, 0), []).makespan == 0
    walled = GridWorld.from_text(".#.\n##.\n...")
    assert plan_jobs(walled, (0, 0), [Job((2, 2), (2, 0))]).status == "unreachable"
    plan = plan_jobs(WORLD, (0, 0), [Job((7, 7), (0, 0))], cap=20)
    assert plan.status == "over_cap" and plan.makespan == 28 and not plan.feasible


def test_paper_objective_needs_the_help_job():
    """Tests the message when the help job is not named."""
    with pytest.raises(ConfigError, match="give help_index"):
        plan_jobs(WORLD, (0, 0), [Job((1, 0), (2, 0))], "paper")


def test_a_job_cannot_dwell_a_negative_time():
    with pytest.raises(ConfigError, match="pallet: dwell must be >= 0"):
        Job((1, 0), (2, 0), dwell=-1, name="pallet")


def test_the_cap_constrains_the_search_not_just_the_answer():
    """Under the paper objective the cheapest order can run past the cap while a dearer
    one fits: the planner must find the dearer one (brute force over orders)."""
    rng = random.Random(99)
    checked = 0
    for _ in range(300):
        jobs = [Job(j.pick, j.drop) for j in random_jobs(rng, rng.randint(2, 5))]
        start = rng.choice(WORLD.free_cells)
        help_index = rng.randrange(len(jobs))
        free = plan_jobs(WORLD, start, jobs, "paper", help_index)
        cap = free.makespan - 1
        best = brute_force(start, jobs, "paper", help_index, cap)
        plan = plan_jobs(WORLD, start, jobs, "paper", help_index, cap=cap)
        if best is None:
            assert plan.status == "over_cap"
        else:
            checked += 1
            assert plan.feasible and plan.makespan <= cap and plan.objective == best
    assert checked > 0
