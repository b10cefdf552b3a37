"""Robots on a grid asking for help in natural language (the paper's Experiment 2).

Grid worlds (:mod:`~ara.coordination.world`), the exact DP planner and the event
STL-to-MILP planner (:mod:`~ara.coordination.planner_dp`,
:mod:`~ara.coordination.planner_milp`), the help protocol
(:mod:`~ara.coordination.protocol`), the Oracle and baselines
(:mod:`~ara.coordination.oracle`) and the experiment
(:mod:`~ara.coordination.experiment2`).
"""

from ara.coordination.planner_dp import Job, Plan, plan_jobs
from ara.coordination.world import GridWorld, WorldError

__all__ = ["GridWorld", "Job", "Plan", "WorldError", "plan_jobs"]
