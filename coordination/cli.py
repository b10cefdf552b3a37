"""``ara coord ...``: the help protocol, its planners, and the paper's Experiment 2."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Literal

import typer

from ara.cli_support import user_errors
from ara.coordination.exp2_config import WAITS, WORDINGS
from ara.coordination.milp import SOLVERS
from ara.coordination.planner_dp import OBJECTIVES
from ara.coordination.protocol import PLANNERS
from ara.coordination.trials import INSTANCES
from ara.errors import ConfigError
from ara.eval.cli import SERVER, Server

# Options with a fixed set of values: the help lists them, and typer refuses others.
Planner = Literal[PLANNERS]
Solver = Literal[tuple(SOLVERS)]
Objective = Literal[OBJECTIVES]
Instances = Literal[INSTANCES]
Wait = Literal[WAITS]
Wordings = Literal[WORDINGS]

coord_app = typer.Typer(help="Multi-robot help requests: Experiment 2, demos, planning.",
                        no_args_is_help=True)


def _translator(llm: str, server: str):
    """None for --model none; else the eval translator over that model."""
    if llm == "none":
        return None
    from ara.eval.translate.models import shared_backend
    from ara.eval.translate.translator import Translator

    return Translator(shared_backend(llm, server=server))


@coord_app.command("exp2", short_help="The paper's Experiment 2 and its baselines.")
def exp2_cmd(
    out: Path = typer.Option(..., "--out", help="Run folder (resumed if it exists)."),
    trials: int = typer.Option(100, "--trials", min=1, help="Number of trials."),
    seed: int = typer.Option(3000, "--seed", help="Seed of trial 0; trial i uses seed + i."),
    planner: Planner = typer.Option("dp", "--planner",
                                    help="dp (exact, fast) or milp (the STL->MILP compiler)."),
    llm: str = typer.Option("none", "--model", "--llm", metavar="none|MODEL",
                            help="none: helpers use the template help spec; else a model "
                                 "that translates each request, as --model of ara translate "
                                 "names it (needs --planner milp)."),
    solver: Solver = typer.Option("highs", "--solver",
                                  help="MILP solver with --planner milp: highs, or gurobi "
                                       "(needs gurobipy and a licence)."),
    objective: Objective = typer.Option(
        "paper", "--objective",
        help="What a helper minimizes: paper (path length + when the requester's wait ends + "
             "what helping adds to its makespan), authors (as Choe et al.'s released code: "
             "its last completion time + path length) or makespan."),
    ils_iterations: int = typer.Option(
        100, "--ils-iterations", min=0,
        help="Iterations of the iterated local search of the Oracle, the baseline that "
             "assigns every robot's work centrally with full knowledge."),
    instances: Instances = typer.Option(
        "paper", "--instances",
        help="paper: trials drawn as Choe et al.'s released code draws them (seeds "
             "3000..3099 give "
             "the paper's instances); uniform: the same distribution from one unbroken "
             "random stream."),
    wait: Wait = typer.Option(
        "arrival", "--wait",
        help="When the requester's wait ends: arrival (the helper reaches the site, the "
             "paper's count) or drop (the pallet is put down, one step later). "
             "summary.json holds both."),
    wordings: Wordings = typer.Option(
        "paper", "--wordings",
        help="paper: every trial's request in the paper's words; all: trial i in wording "
             "i mod 11 (the paper's and ten rewordings), to test a translator (--model)."),
    processes: int = typer.Option(1, "--processes", min=1,
                                  help="Trials run in parallel (joblib processes); with "
                                       "--model, one at a time, over the one loaded model."),
    server: Server = SERVER,
) -> None:
    """Reproduce the paper's Experiment 2: trials.csv, summary.json, boxplot.png in OUT."""
    from ara.coordination.experiment2 import Exp2Config, run, table

    with user_errors():
        config = Exp2Config(trials=trials, seed=seed, planner=planner, llm=llm, solver=solver,
                            objective=objective, ils_iterations=ils_iterations,
                            instances=instances, wait=wait, wordings=wordings)
        if solver != "highs":
            from ara.coordination.milp import make_solver

            make_solver(solver)  # fails now, with its reason, rather than in a worker
        factory = (lambda: _translator(llm, server)) if llm != "none" else None
        summary = run(config, out, processes, factory)
    typer.echo(table(summary))
    typer.echo(json.dumps(summary["comparisons"], indent=2))
    typer.echo(f"wrote {out}/trials.csv, summary.json, boxplot.png")


@coord_app.command("demo", short_help="One of the paper's demonstrations.")
def demo_cmd(
    name: str = typer.Argument(..., metavar="NAME", help="pallet, kitting or tool."),
    out: Path = typer.Option(Path("runs/demos"), "--out", help="Folder for the PNG and JSON."),
    llm: str = typer.Option("none", "--model", "--llm", metavar="none|MODEL",
                            help="none: the reference STL; else a model that translates, "
                                 "as --model of ara translate names it."),
    server: Server = SERVER,
) -> None:
    """Run one of the paper's demonstrations: messages, STL, plan, and a PNG of the paths."""
    from ara.coordination.demos import DEMOS, run_demo

    with user_errors():
        if name not in DEMOS:  # before a model loads
            raise ConfigError(f"unknown demo {name!r}: choose one of {', '.join(DEMOS)}")
        run_demo(name, out, _translator(llm, server), typer.echo)


@coord_app.command("plan", short_help="Plan one robot's path for an STL spec.")
def plan_cmd(
    stl: str = typer.Argument(..., metavar="FORMULA",
                              help="A formula over the names given with --at."),
    at: list[str] = typer.Option(..., "--at", metavar="NAME=ROW,COL",
                                 help="The grid cell of each proposition of FORMULA, "
                                      "repeated: --at a=0,7 --at b=7,7."),
    start: str = typer.Option("0,0", "--start", metavar="ROW,COL",
                              help="Where the robot starts."),
    world_file: Path = typer.Option(
        None, "--world",
        help="Grid file: one line a row, '.' free, '#' obstacle [default: the paper's 8x8]."),
    objective: Objective = typer.Option(
        "makespan", "--objective", help="makespan, paper or authors (as ara coord exp2's)."),
    cap: int = typer.Option(None, "--cap", min=0,
                            help="Largest makespan allowed, in time steps (one grid move each)."),
    solver: Solver = typer.Option("highs", "--solver",
                                  help="highs, or gurobi (needs gurobipy and a licence)."),
    as_json: bool = typer.Option(False, "--json", help="One JSON object."),
) -> None:
    """Plan a robot's path for an STL spec with the event MILP: each event's time is a
    variable, and the formula's orders and windows constrain them (no plan: exit 1)."""
    from dataclasses import asdict

    from ara.cli_support import emit
    from ara.coordination.events import Vocabulary
    from ara.coordination.milp import make_solver
    from ara.coordination.planner_milp import plan_spec
    from ara.coordination.world import GridWorld
    from ara.grammars import parse

    def cell(text: str):
        try:
            r, c = (int(x) for x in text.split(","))
        except ValueError:
            raise ConfigError(f"a cell is ROW,COL, got {text!r}") from None
        return r, c

    with user_errors():
        world = GridWorld.from_file(world_file) if world_file else GridWorld.paper()
        places = {}
        for item in at:
            name, _, where = item.partition("=")
            if not where:
                raise ConfigError(f"--at takes NAME=ROW,COL, got {item!r}")
            places[name] = cell(where)
        plan = plan_spec(world, cell(start), {"task": parse(stl)}, Vocabulary(places),
                         objective, cap, make_solver(solver))
    emit(asdict(plan), as_json, lambda p: (
        f"{p['status']}: " + " -> ".join(f"{e}@{p['times'][e]}" for e in p["order"])
        + f"  makespan {p['makespan']}, {p['solve_s'] * 1000:.1f} ms"))
    if not plan.feasible:
        raise typer.Exit(1)
