"""Planning speed for Experiment 2, measured side by side in one run.

1. Per helper offer on the paper's instances (every forklift of the first trials
   bidding for the help job): the exact DP vs the event-based STL->MILP solved by
   HiGHS and by Gurobi (the pip wheel's license), with identical bids asserted.
2. The whole experiment (all five methods) with the DP planner, wall time.

    .venv/bin/python bench/coord_planners.py [--trials 20] [--exp2-trials 100] [--processes 2]
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import tempfile
import time

from ara.coordination.experiment2 import CAPABILITIES, Exp2Config, run
from ara.coordination.milp import make_solver
from ara.coordination.oracle import Fleet, exact
from ara.coordination.protocol import Helper, HelpRequest, make_offer, request_text
from ara.coordination.trials import PAPER_WORLD, make_trial

PLANNERS = {"dp": ("dp", "highs"), "milp-highs": ("milp", "highs"),
            "milp-gurobi": ("milp", "gurobi")}


def offers(trials: int) -> None:
    times = {name: [] for name in PLANNERS}
    solvers = {name: make_solver(solver) for name, (_, solver) in PLANNERS.items()}
    for i in range(trials):
        trial = make_trial(i, 3000 + i)
        before = exact(Fleet(PAPER_WORLD, trial.starts, trial.jobs))
        request = HelpRequest("r", trial.site, CAPABILITIES, request_text(trial.site, CAPABILITIES))
        for k, route in enumerate(before.routes):
            helper = Helper(k, trial.starts[k], tuple(trial.jobs[j] for j in route))
            bids = {}
            for name, (planner, _) in PLANNERS.items():
                t0 = time.perf_counter()
                o = make_offer(PAPER_WORLD, helper, request, planner=planner,
                               solver=solvers[name])
                times[name].append(time.perf_counter() - t0)
                bids[name] = (o.can_help, o.tau_help, o.tau_new)
            assert len(set(bids.values())) == 1, (i, k, bids)
    median = {name: statistics.median(times[name]) * 1000 for name in PLANNERS}
    print(f"\n## Per helper offer ({len(times['dp'])} offers, {trials} trials; equal bids)\n")
    print("| planner | median ms | mean ms | max ms |\n|---|---:|---:|---:|")
    for name in PLANNERS:
        ms = [t * 1000 for t in times[name]]
        print(f"| {name} | {statistics.median(ms):.2f} | {statistics.fmean(ms):.2f} | "
              f"{max(ms):.1f} |")
    print(f"\nmedian ratios: MILP (HiGHS) / DP {median['milp-highs'] / median['dp']:.0f}x, "
          f"Gurobi / HiGHS {median['milp-gurobi'] / median['milp-highs']:.2f}x")


def experiment(trials: int, processes: int) -> None:
    with tempfile.TemporaryDirectory() as out:
        t0 = time.perf_counter()
        run(Exp2Config(trials=trials), out, n_jobs=processes, progress=False)
        wall = time.perf_counter() - t0
    print(f"\n## Experiment 2, all five methods, DP planner\n\n{trials} trials, "
          f"{processes} process(es): {wall:.1f} s wall ({wall / trials:.2f} s per trial)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=20)
    parser.add_argument("--exp2-trials", type=int, default=100)
    parser.add_argument("--processes", type=int, default=2,
                        help="trials run in parallel (processes)")
    args = parser.parse_args()
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"Python {platform.python_version()}")
    offers(args.trials)
    experiment(args.exp2_trials, args.processes)


if __name__ == "__main__":
    main()
