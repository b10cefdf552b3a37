"""The centralized Oracle: exact MILP vs brute force; ILS between greedy and exact."""

import itertools
import random

import pytest

from ara.coordination.oracle import (
    Fleet,
    FleetError,
    ILSSettings,
    evaluate,
    exact,
    greedy_insertion,
    ils,
)
from ara.coordination.planner_dp import Job
from ara.coordination.trials import make_trial
from ara.coordination.world import GridWorld, WorldError
from ara.errors import ConfigError

WORLD = GridWorld.paper()


def brute_force(fleet):
    """Least cost over every assignment of jobs to robots and every order."""
    n, k = len(fleet.jobs), len(fleet.starts)
    best = None
    for owners in itertools.product(range(k), repeat=n):
        per_robot = [[j for j in range(n) if owners[j] == r] for r in range(k)]
        for orders in itertools.product(*(itertools.permutations(js) for js in per_robot)):
            s = evaluate(fleet, orders)
            if s.feasible and (best is None or s.cost < best):
                best = s.cost
    return best


def small_fleet(rng, help_job=True, cap=None):
    cells = WORLD.free_cells
    jobs = tuple(Job(rng.choice(cells), rng.choice(cells)) for _ in range(rng.randint(1, 4)))
    starts = tuple(rng.choice(cells) for _ in range(rng.randint(1, 3)))
    return Fleet(WORLD, starts, jobs, rng.randrange(len(jobs)) if help_job else None, cap)


def test_exact_oracle_equals_brute_force():
    """Tests 25 small fleets (1-3 robots, 1-4 jobs, with and without a help job and a
    cap): the MILP's optimum is the least cost over all assignments and orders."""
    rng = random.Random(11)
    for k in range(25):
        fleet = small_fleet(rng, help_job=k % 2 == 0, cap=rng.choice([None, 25]))
        expected = brute_force(fleet)
        got = exact(fleet)
        if expected is None:
            assert got.status == "infeasible"
        else:
            assert got.status == "optimal" and got.cost == expected and got.feasible
            assert sorted(j for r in got.routes for j in r) == list(range(len(fleet.jobs)))


def test_pinned_job_stays_with_its_robot():
    trial = make_trial(0, 3000)
    jobs = (*trial.jobs, trial.help_job)
    fleet = Fleet(WORLD, trial.starts, jobs, help_job=len(jobs) - 1)
    free, pinned = exact(fleet), exact(fleet, pinned={len(jobs) - 1: 5})
    assert len(jobs) - 1 in pinned.routes[5]
    assert pinned.cost >= free.cost


@pytest.mark.parametrize("seed", [3000, 3001, 3002])
def test_ils_is_never_worse_than_greedy_nor_better_than_the_optimum(seed):
    trial = make_trial(0, seed)
    fleet = Fleet(WORLD, trial.starts, (*trial.jobs, trial.help_job), help_job=12, cap=50)
    greedy = evaluate(fleet, greedy_insertion(fleet))
    found = ils(fleet, ILSSettings(iterations=20, seed=seed))
    optimum = exact(fleet)
    assert optimum.cost <= found.cost <= greedy.cost
    assert found.feasible and sorted(j for r in found.routes for j in r) == list(range(13))


def test_ils_improves_on_the_greedy_insertion_it_starts_from():
    """Tests that the search does more than return its start: on this trial greedy
    insertion leaves the optimum far behind."""
    trial = make_trial(0, 3002)
    fleet = Fleet(WORLD, trial.starts, (*trial.jobs, trial.help_job), help_job=12, cap=50)
    greedy = evaluate(fleet, greedy_insertion(fleet))
    assert exact(fleet).cost < greedy.cost  # room to improve
    assert ils(fleet, ILSSettings(iterations=20, seed=3002)).cost < greedy.cost


def test_settings_and_fleets_check_their_ranges():
    """A zero temperature accepts improvements only; impossible values are refused."""
    fleet = Fleet(WORLD, ((0, 0), (7, 7)), (Job((0, 2), (0, 3)), Job((7, 5), (7, 6))))
    assert ils(fleet, ILSSettings(temperature=0, iterations=5)).feasible
    with pytest.raises(ConfigError, match="temperature >= 0"):
        ILSSettings(temperature=-1)
    with pytest.raises(ConfigError, match="perturb_moves >= 1"):
        ILSSettings(perturb_moves=0)
    with pytest.raises(FleetError, match="at least one robot"):
        Fleet(WORLD, (), (Job((0, 2), (0, 3)),))
    with pytest.raises(FleetError, match="not a job index"):
        Fleet(WORLD, ((0, 0),), (Job((0, 2), (0, 3)),), help_job=3)
    with pytest.raises(WorldError, match="is an obstacle"):
        Fleet(WORLD, ((1, 1),), (Job((0, 2), (0, 3)),))


def test_unreachable_jobs_are_a_clear_error():
    walled = GridWorld.from_text("..#.\n..#.\n")
    fleet = Fleet(walled, ((0, 0),), (Job((0, 3), (1, 3)),))
    with pytest.raises(FleetError, match="no path from"):
        exact(fleet)
