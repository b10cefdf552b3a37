"""A solver-neutral MILP: build it once, solve it with HiGHS (default) or Gurobi.

The planners write their models against :class:`LinearModel`; a :class:`MILPSolver`
turns one into a :class:`Solution`. HiGHS ships with the toolkit (``highspy``); Gurobi
is used only when asked for (``--solver gurobi``) and when ``gurobipy`` and a license are
present. Its pip license is limited to 2,000 variables and constraints, which the
event-based plans stay far below.

A solver never raises on an infeasible or unfinished model: the status says so, and
callers plan with any status that carries a solution
(:data:`ara.coordination.status.WITH_SOLUTION`) and turn the others into "cannot help".
"""

from __future__ import annotations

import contextlib
import os
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Protocol

from ara.coordination.status import WITH_SOLUTION, Status, checked
from ara.errors import AraError, ConfigError

INF = float("inf")


@dataclass
class LinearModel:
    """Minimize ``sum(cost * x)`` subject to ``lo <= sum(coef * x) <= hi`` rows.

    Variables are added by name; a row is a ``{name: coefficient}`` mapping.
    """

    names: list[str] = field(default_factory=list)
    lower: list[float] = field(default_factory=list)
    upper: list[float] = field(default_factory=list)
    integer: list[bool] = field(default_factory=list)
    cost: list[float] = field(default_factory=list)
    rows: list[tuple[dict[int, float], float, float]] = field(default_factory=list)
    index: dict[str, int] = field(default_factory=dict)

    def var(self, name: str, lo: float = 0.0, hi: float = INF, integer: bool = False,
            cost: float = 0.0) -> str:
        if name in self.index:
            raise ValueError(f"variable {name!r} added twice")
        self.index[name] = len(self.names)
        self.names.append(name)
        self.lower.append(lo)
        self.upper.append(hi)
        self.integer.append(integer)
        self.cost.append(cost)
        return name

    def binary(self, name: str, cost: float = 0.0) -> str:
        return self.var(name, 0.0, 1.0, True, cost)

    def add_cost(self, name: str, cost: float) -> None:
        self.cost[self.index[name]] += cost

    def row(self, terms: dict[str, float], lo: float = -INF, hi: float = INF) -> None:
        merged: dict[int, float] = {}
        for name, coef in terms.items():
            j = self.index[name]
            merged[j] = merged.get(j, 0.0) + coef
        self.rows.append(({j: c for j, c in merged.items() if c}, lo, hi))

    def le(self, terms: dict[str, float], rhs: float) -> None:
        self.row(terms, hi=rhs)

    def ge(self, terms: dict[str, float], rhs: float) -> None:
        self.row(terms, lo=rhs)

    def eq(self, terms: dict[str, float], rhs: float) -> None:
        self.row(terms, lo=rhs, hi=rhs)

    @property
    def size(self) -> dict[str, int]:
        return {"variables": len(self.names), "integer": sum(self.integer),
                "constraints": len(self.rows)}


@dataclass(frozen=True)
class Solution:
    """What a solver made of a model.

    Attributes:
        status: One of ``optimal``, ``feasible`` (stopped with a solution, not proven),
            ``infeasible``, ``time_limit`` (stopped without a solution) or ``error``.
        objective: Objective value, when there is a solution.
        values: Variable values by name, when there is a solution.
        gap: Relative MIP gap reported by the solver.
        solve_s: Wall time of the solve.
        message: The solver's own words when it failed.
    """

    status: Status
    objective: float | None = None
    values: dict[str, float] = field(default_factory=dict)
    gap: float | None = None
    solve_s: float = 0.0
    message: str = ""

    def __post_init__(self) -> None:
        checked(self.status)

    @property
    def has_solution(self) -> bool:
        return self.status in WITH_SOLUTION


class MILPSolver(Protocol):
    name: str

    def solve(self, model: LinearModel, time_limit_s: float = 10.0) -> Solution: ...


@contextlib.contextmanager
def _stdout_silenced() -> Iterator[None]:
    """Send file descriptor 1 to the null device for the block.

    HiGHS 1.16 prints its banner from C++ while ``Highs()`` is constructed, before
    ``output_flag`` can be set, and ``ara coord plan --json`` must keep stdout pure JSON.
    """
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 1)
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)


class HiGHSSolver:
    """HiGHS through ``highspy``, one thread, quiet."""

    name = "highs"

    def __init__(self, threads: int = 1) -> None:
        self.threads = threads

    def solve(self, model: LinearModel, time_limit_s: float = 10.0) -> Solution:
        import highspy
        import numpy as np

        with _stdout_silenced():
            h = highspy.Highs()
            h.setOptionValue("output_flag", False)
        h.setOptionValue("threads", self.threads)
        h.setOptionValue("time_limit", float(time_limit_s))
        h.setOptionValue("mip_rel_gap", 0.0)
        inf = h.getInfinity()

        def clip(v: float) -> float:
            return inf if v == INF else -inf if v == -INF else v

        n = len(model.names)
        h.addVars(n, np.array([clip(v) for v in model.lower]),
                  np.array([clip(v) for v in model.upper]))
        h.changeColsCost(n, np.arange(n, dtype=np.int32), np.array(model.cost, dtype=float))
        ints = [j for j in range(n) if model.integer[j]]
        if ints:
            h.changeColsIntegrality(len(ints), np.array(ints, dtype=np.int32),
                                    np.array([highspy.HighsVarType.kInteger] * len(ints)))
        for terms, lo, hi in model.rows:
            idx = np.array(list(terms), dtype=np.int32)
            h.addRow(clip(lo), clip(hi), len(idx), idx, np.array(list(terms.values())))
        start = time.perf_counter()
        h.run()
        elapsed = time.perf_counter() - start
        status = h.getModelStatus()
        S = highspy.HighsModelStatus
        info = h.getInfo()
        has_primal = info.primal_solution_status == 2
        if status == S.kOptimal:
            kind = "optimal"
        elif status == S.kInfeasible:
            kind = "infeasible"
        elif status in (S.kTimeLimit, S.kIterationLimit, S.kInterrupt):
            kind = "feasible" if has_primal else "time_limit"
        else:
            kind = "error"
        if kind not in ("optimal", "feasible"):
            return Solution(kind, solve_s=elapsed)
        x = h.getSolution().col_value
        gap = info.mip_gap if ints else 0.0
        return Solution(kind, h.getInfo().objective_function_value,
                        dict(zip(model.names, x, strict=True)), gap, elapsed)


#: gurobipy's error number for a model beyond the size-limited license that comes with
#: the pip wheel (2,000 variables and 2,000 linear constraints).
GUROBI_SIZE_LIMITED = 10010


class SolverLicenseError(AraError, RuntimeError):
    """The solver's license does not cover this model."""


class GurobiSolver:
    """Gurobi through ``gurobipy``. The pip wheel's bundled license solves models of up
    to 2,000 variables and 2,000 constraints offline, which every model of Experiment 2
    stays under; a larger one raises :class:`SolverLicenseError`."""

    name = "gurobi"

    def __init__(self, threads: int = 1) -> None:
        try:
            import gurobipy  # noqa: F401
        except ImportError as err:
            raise ConfigError("--solver gurobi needs gurobipy (pip install gurobipy) and a "
                              "license; the default solver is highs") from err
        self.threads = threads

    def solve(self, model: LinearModel, time_limit_s: float = 10.0) -> Solution:
        import gurobipy as gp

        env = gp.Env(params={"OutputFlag": 0})
        m = gp.Model(env=env)
        m.Params.Threads, m.Params.TimeLimit, m.Params.MIPGap = self.threads, time_limit_s, 0.0
        xs = [m.addVar(lb=lo if lo != -INF else -gp.GRB.INFINITY,
                       ub=hi if hi != INF else gp.GRB.INFINITY, obj=c,
                       vtype=gp.GRB.INTEGER if integer else gp.GRB.CONTINUOUS, name=name)
              for name, lo, hi, integer, c in zip(model.names, model.lower, model.upper,
                                                  model.integer, model.cost, strict=True)]
        for terms, lo, hi in model.rows:
            expr = gp.quicksum(c * xs[j] for j, c in terms.items())
            if lo == hi:
                m.addConstr(expr == lo)
            else:
                if lo != -INF:
                    m.addConstr(expr >= lo)
                if hi != INF:
                    m.addConstr(expr <= hi)
        start = time.perf_counter()
        try:
            m.optimize()
        except gp.GurobiError as err:
            if err.errno == GUROBI_SIZE_LIMITED:
                raise SolverLicenseError(
                    f"this model has {len(xs)} variables and {m.NumConstrs} constraints, "
                    "more than the size-limited Gurobi license of the pip wheel allows "
                    "(2,000 each); use --solver highs, or install a full Gurobi "
                    "license") from err
            return Solution("error", solve_s=time.perf_counter() - start, message=str(err))
        elapsed = time.perf_counter() - start
        G = gp.GRB
        if m.Status == G.OPTIMAL:
            kind = "optimal"
        elif m.Status in (G.INFEASIBLE, G.INF_OR_UNBD):
            kind = "infeasible"
        elif m.Status == G.TIME_LIMIT:
            kind = "feasible" if m.SolCount else "time_limit"
        else:
            kind = "error"
        if kind not in ("optimal", "feasible"):
            return Solution(kind, solve_s=elapsed)
        return Solution(kind, m.ObjVal, {v.VarName: v.X for v in xs}, m.MIPGap, elapsed)


SOLVERS = {"highs": HiGHSSolver, "gurobi": GurobiSolver}


def make_solver(name: str = "highs") -> MILPSolver:
    """The solver called ``name`` (``highs`` or ``gurobi``)."""
    if name not in SOLVERS:
        raise ConfigError(f"unknown solver {name!r}; choose one of {sorted(SOLVERS)}")
    return SOLVERS[name]()
