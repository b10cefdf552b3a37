"""Robots on a grid asking for help in natural language (the paper's Experiment 2).

Landed so far: grid worlds and the exact DP planner. The STL-to-MILP compiler, the
help protocol, the Oracle and the baselines come with the rest of their issue.
"""

from ara.coordination.planner_dp import Job, Plan, plan_jobs
from ara.coordination.world import GridWorld, WorldError

__all__ = ["GridWorld", "Job", "Plan", "WorldError", "plan_jobs"]
