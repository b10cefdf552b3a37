"""Experiment 2's settings: what a run is (recorded in ``run.json``, and a resumed run
must be the same)."""

from __future__ import annotations

from dataclasses import dataclass

from ara.coordination.milp import SOLVERS
from ara.coordination.planner_dp import OBJECTIVES
from ara.coordination.protocol import PLANNERS
from ara.coordination.trials import INSTANCES
from ara.errors import ConfigError

METHODS = ("ours", "oracle_ils", "oracle_exact", "b2", "b3")
CAPABILITIES = ("navigate", "report conflicts")
WAITS = ("arrival", "drop")
WORDINGS = ("paper", "all")


@dataclass(frozen=True)
class Exp2Config:
    """One experiment's settings (recorded in ``run.json``; ``ara coord exp2 --help``
    says what each does).

    ``llm`` is ``--model``: ``none`` (helpers plan the template spec) or the model that
    translates each request; its name is the one earlier run folders recorded.
    """

    trials: int = 100
    seed: int = 3000
    robots: int = 6
    jobs: int = 12
    cap: int = 50
    planner: str = "dp"
    objective: str = "paper"
    llm: str = "none"
    solver: str = "highs"
    ils_iterations: int = 100
    instances: str = "paper"
    wait: str = "arrival"
    wordings: str = "paper"

    def __post_init__(self) -> None:
        if (self.trials < 1 or self.robots < 1 or self.jobs < 0 or self.cap < 1
                or self.ils_iterations < 0):
            raise ConfigError(
                "need trials >= 1, robots >= 1, jobs >= 0, cap >= 1 and ils_iterations >= 0; "
                f"got {self.trials}, {self.robots}, {self.jobs}, {self.cap}, "
                f"{self.ils_iterations}")
        if self.objective not in OBJECTIVES:
            raise ConfigError(f"--objective must be one of {OBJECTIVES}, got {self.objective!r}")
        if self.instances not in INSTANCES:
            raise ConfigError(f"--instances must be one of {INSTANCES}, got {self.instances!r}")
        if self.wordings not in WORDINGS:
            raise ConfigError(f"--wordings must be one of {WORDINGS}, got {self.wordings!r}")
        if self.wait not in WAITS:
            raise ConfigError(f"--wait must be one of {WAITS}, got {self.wait!r}")
        if self.planner not in PLANNERS:
            raise ConfigError(f"--planner must be one of {PLANNERS}, got {self.planner!r}")
        if self.solver not in SOLVERS:
            raise ConfigError(f"--solver must be one of {tuple(SOLVERS)}, got {self.solver!r}")
        if self.llm != "none" and self.planner == "dp":
            raise ConfigError("a translated help request can say anything STL can: plan it "
                              "with --planner milp (the DP handles the template spec only)")
