"""Experiment 2's instances: a help site, forklift starts and pick-and-place jobs.

Two ways to draw trial ``s`` (a seed; the paper's run uses 3000..3099):

* ``paper`` draws what the authors' code draws, so that results can be set beside
  the paper's. Python's ``random`` only, free cells in row-major order, and the
  generator re-seeded with ``s`` before each of three steps:

  1. the help site, one uniform draw (``sample(free, 1)``);
  2. the starts, each a ``choice`` among the free cells other than the site, with
     replacement;
  3. the jobs in blocks of four: ``choices(free, k=4)`` for the picks, then
     ``choices(free, k=4)`` for the drops; jobs are the blocks' pairs in order, and a
     pick may equal its drop.

  docs/coordination.md says how this was checked against the authors' instances.
* ``uniform`` draws the same distribution from one unbroken stream (site, then
  starts, then each job's pick and drop).

The help job's drop cell is the site's nearest free neighbour in a fixed order, for
both: the authors draw a random neighbour after their Oracle's random calls, which no
re-draw can follow.
"""

from __future__ import annotations

import random
from dataclasses import dataclass

from ara.coordination.planner_dp import Job
from ara.coordination.world import Cell, GridWorld
from ara.errors import ConfigError

PAPER_WORLD = GridWorld.paper()
INSTANCES = ("paper", "uniform")
#: The authors draw picks and drops four jobs at a time.
PAPER_BLOCK = 4


@dataclass(frozen=True)
class Trial:
    """One instance: where help is needed, where the forklifts start, their jobs."""

    index: int
    seed: int
    site: Cell
    starts: tuple[Cell, ...]
    jobs: tuple[Job, ...]

    @property
    def help_job(self) -> Job:
        return Job(self.site, PAPER_WORLD.nearest_free_neighbour(self.site), name="help")

    @property
    def handover_steps(self) -> int:
        """Steps from the site to the help job's drop cell: the requester's wait counted
        until the helper *arrives* (the paper's) is this much shorter than the wait
        counted until the pallet is dropped."""
        help_job = self.help_job
        steps = PAPER_WORLD.distance(help_job.pick, help_job.drop)
        assert steps is not None  # the drop cell is a free neighbour of the site
        return steps


def make_trial(index: int, seed: int, robots: int = 6, jobs: int = 12,
               instances: str = "paper") -> Trial:
    """Trial ``index`` on the paper's grid, drawn from ``seed`` as ``instances`` says (see
    the module doc)."""
    if instances not in INSTANCES:
        raise ConfigError(f"instances must be one of {INSTANCES}, got {instances!r}")
    draw = _paper_draw if instances == "paper" else _uniform_draw
    site, starts, drawn = draw(seed, robots, jobs, PAPER_WORLD.free_cells)
    return Trial(index, seed, site, starts, drawn)


def _paper_draw(seed: int, robots: int, jobs: int, free: tuple[Cell, ...]):
    free = list(free)
    rng = random.Random(seed)
    site = rng.sample(free, 1)[0]
    rng.seed(seed)
    others = [c for c in free if c != site]
    starts = tuple(rng.choice(others) for _ in range(robots))
    rng.seed(seed)
    pairs: list[tuple[Cell, Cell]] = []
    while len(pairs) < jobs:
        picks = rng.choices(free, k=PAPER_BLOCK)
        drops = rng.choices(free, k=PAPER_BLOCK)
        pairs.extend(zip(picks, drops, strict=True))
    drawn = tuple(Job(p, d, name=f"j{k}") for k, (p, d) in enumerate(pairs[:jobs]))
    return site, starts, drawn


def _uniform_draw(seed: int, robots: int, jobs: int, free: tuple[Cell, ...]):
    free = list(free)
    rng = random.Random(seed)
    site = rng.choice(free)
    others = [c for c in free if c != site]
    starts = tuple(rng.choice(others) for _ in range(robots))
    drawn = tuple(Job(rng.choice(free), rng.choice(free), name=f"j{k}") for k in range(jobs))
    return site, starts, drawn


def closest_robot(trial: Trial) -> int:
    """The authors' "closest": Manhattan distance from the start cell, lowest id on ties."""
    return min(range(len(trial.starts)),
               key=lambda k: (abs(trial.starts[k][0] - trial.site[0])
                              + abs(trial.starts[k][1] - trial.site[1]), k))
