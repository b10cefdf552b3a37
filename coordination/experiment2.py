"""The paper's Experiment 2: who should move the pallet, and what does it cost?

Per trial (``../shared/specs/experiment2.md``; seeds 3000..3099): an 8x8 grid, a help
site, 6 forklifts, 12 pick-and-place jobs, a makespan cap of 50. The exact Oracle
schedules the 12 jobs once (S_orig); then each method places the help job and the
metric is the time added to the system,

    Delta = (sum of makespans + the requester's wait, after) - (sum of makespans, before)

Methods: ``ours`` (the NL help protocol: every forklift bids, the requester takes the
least tau_help + tau_new), ``oracle_ils`` (the paper's Oracle: greedy insertion +
ILS over all 13 jobs), ``oracle_exact`` (the proven optimum), ``b2`` (the forklift
closest to the site, by Manhattan distance from its start as in the authors' code,
adds the help job; nothing else changes) and ``b3`` (that forklift takes the help
job and the exact Oracle re-optimizes everything else).

Each finished trial is appended to ``trials.jsonl`` at once, so an interrupted run
resumes where it stopped; ``trials.csv``, ``summary.json`` and ``boxplot.png`` are
written from it at the end.
"""

from __future__ import annotations

import csv
import json
import random
import statistics
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path

from ara.coordination.milp import make_solver
from ara.coordination.oracle import Fleet, ILSSettings, exact, ils
from ara.coordination.planner_dp import Job
from ara.coordination.protocol import (
    Helper,
    HelpRequest,
    choose,
    make_offer,
    request_text,
)
from ara.coordination.world import Cell, GridWorld
from ara.errors import ConfigError

METHODS = ("ours", "oracle_ils", "oracle_exact", "b2", "b3")
CAPABILITIES = ("navigate", "report conflicts")


@dataclass(frozen=True)
class Exp2Config:
    """One experiment's settings (recorded in ``run.json``)."""

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

    def __post_init__(self) -> None:
        if (self.trials < 1 or self.robots < 1 or self.jobs < 0 or self.cap < 1
                or self.ils_iterations < 0):
            raise ConfigError(
                "need trials >= 1, robots >= 1, jobs >= 0, cap >= 1 and ils_iterations >= 0; "
                f"got {self.trials}, {self.robots}, {self.jobs}, {self.cap}, "
                f"{self.ils_iterations}")
        if self.planner not in ("dp", "milp"):
            raise ConfigError(f"--planner must be dp or milp, got {self.planner!r}")
        if self.llm != "none" and self.planner == "dp":
            raise ConfigError("a translated help request can say anything STL can: plan it "
                              "with --planner milp (the DP handles the template spec only)")


@dataclass(frozen=True)
class Trial:
    """One random instance."""

    index: int
    seed: int
    site: Cell
    starts: tuple[Cell, ...]
    jobs: tuple[Job, ...]

    @property
    def help_job(self) -> Job:
        return Job(self.site, PAPER_WORLD.nearest_free_neighbour(self.site), name="help")


PAPER_WORLD = GridWorld.paper()


def make_trial(index: int, seed: int, robots: int = 6, jobs: int = 12,
               world: GridWorld = PAPER_WORLD) -> Trial:
    """The spec's draw: site, then starts (not on the site), then jobs, from one RNG."""
    rng = random.Random(seed)
    free = list(world.free_cells)
    site = rng.choice(free)
    others = [c for c in free if c != site]
    starts = tuple(rng.choice(others) for _ in range(robots))
    drawn = tuple(Job(rng.choice(free), rng.choice(free), name=f"j{k}") for k in range(jobs))
    return Trial(index, seed, site, starts, drawn)


def closest_robot(trial: Trial) -> int:
    """The authors' "closest": Manhattan distance from the start cell, lowest id on ties."""
    return min(range(len(trial.starts)),
               key=lambda k: (abs(trial.starts[k][0] - trial.site[0])
                              + abs(trial.starts[k][1] - trial.site[1]), k))


def run_trial(trial: Trial, config: Exp2Config, translator=None) -> list[dict]:
    """All methods on one trial; one row per method."""
    world = PAPER_WORLD
    solver = make_solver(config.solver)
    started = time.perf_counter()
    before = exact(Fleet(world, trial.starts, trial.jobs, cap=config.cap), solver)
    before_s = time.perf_counter() - started
    if before.status != "optimal":
        raise RuntimeError(f"trial {trial.index}: the 12-job schedule failed ({before.status})")
    rows = []

    def row(method: str, delta, helper=None, solve_s=0.0, **extra) -> None:
        rows.append({"trial": trial.index, "seed": trial.seed, "method": method,
                     "delta": delta, "helper": helper, "solve_s": round(solve_s, 6),
                     "feasible": delta is not None, **extra})

    helpers = [Helper(k, trial.starts[k], tuple(trial.jobs[j] for j in route))
               for k, route in enumerate(before.routes)]
    request = HelpRequest("requester", trial.site, CAPABILITIES,
                          request_text(trial.site, CAPABILITIES))
    options = {"planner": config.planner, "objective": config.objective, "cap": config.cap,
               "translator": translator, "solver": solver}
    offers, offer_s = [], []
    for h in helpers:
        t0 = time.perf_counter()
        offers.append(make_offer(world, h, request, **options))
        offer_s.append(time.perf_counter() - t0)
    chosen = choose(offers)
    if chosen is None:
        row("ours", None, None, sum(offer_s), reason="no helper could help")
    else:
        o = offers[chosen]
        row("ours", o.bid, chosen, sum(offer_s), tau_help=o.tau_help, tau_new=o.tau_new,
            stl=o.stl)

    # B2 is the nearest forklift's own offer, whether or not it won the auction
    near = closest_robot(trial)
    o = offers[near]
    row("b2", o.bid if o.can_help else None, near, offer_s[near],
        tau_help=o.tau_help, tau_new=o.tau_new, reason=o.reason)

    fleet = Fleet(world, trial.starts, (*trial.jobs, trial.help_job), help_job=len(trial.jobs),
                  cap=config.cap)
    for method, solve in (
        ("oracle_exact", lambda: exact(fleet, solver)),
        ("oracle_ils", lambda: ils(fleet, ILSSettings(config.ils_iterations, seed=trial.seed))),
        ("b3", lambda: exact(fleet, solver, pinned={len(trial.jobs): near})),
    ):
        t0 = time.perf_counter()
        s = solve()  # a failed solve has no routes and is not feasible
        helper = next((k for k, r in enumerate(s.routes) if len(trial.jobs) in r), None)
        row(method, s.cost - before.cost if s.feasible else None, helper,
            time.perf_counter() - t0,
            wait=s.help_time)
    for r in rows:
        r["before"] = before.cost
        r["before_s"] = round(before_s, 6)
    return rows


# -- the run --------------------------------------------------------------------------
def run(config: Exp2Config, out: str | Path, n_jobs: int = 1, translator_factory=None,
        progress: bool = True) -> dict:
    """Run (or resume) the experiment into ``out``; returns the summary."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    record = out / "run.json"
    settings = asdict(config)
    # The translator first: its model hash belongs to the run's identity, so a resumed
    # run cannot mix answers of two adapters.
    translator = SharedTranslator(translator_factory()) if translator_factory else None
    model = translator.backend.model_id if translator else None
    if record.exists():
        old = json.loads(record.read_text())
        if (old["config"], old.get("translator")) != (settings, model):
            raise ConfigError(f"{out} holds a run with other settings ({old['config']}, "
                              f"translator {old.get('translator')}); choose another --out "
                              "or delete it")
    else:
        from ara.provenance import git_commit

        record.write_text(json.dumps({"config": settings, "translator": model,
                                      "git_commit": git_commit()}, indent=2) + "\n")
    store = out / "trials.jsonl"
    done = _load_rows(store)
    # Keep only whole trials: a line cut by an interruption, or a trial with some of its
    # methods missing, would otherwise sit in front of what is appended next.
    tmp = store.with_suffix(".tmp")
    tmp.write_text("".join(json.dumps(r) + "\n" for r in done))
    tmp.replace(store)
    finished = {r["trial"] for r in done}
    todo = [make_trial(i, config.seed + i, config.robots, config.jobs)
            for i in range(config.trials) if i not in finished]
    from tqdm import tqdm

    bar = tqdm(total=config.trials, initial=config.trials - len(todo), desc="exp2",
               unit="trial", disable=not progress)
    with store.open("a") as sink:
        for rows in _map(todo, config, n_jobs, translator):
            for r in rows:
                sink.write(json.dumps(r) + "\n")
            sink.flush()
            bar.update()
    bar.close()
    rows = _load_rows(store)
    write_csv(rows, out / "trials.csv")
    summary = summarize(rows, config)
    (out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    plot(rows, out / "boxplot.png")
    return summary


class SharedTranslator:
    """One translator for all simulated helpers of a process.

    Every helper runs the same model and grammar with greedy decoding, so they would
    all get the same formula for the same request; computing it once per request
    changes no result, only the run time (6x fewer generations).
    """

    def __init__(self, translator) -> None:
        self.translator, self.backend, self._memo = translator, translator.backend, {}

    def translate(self, nl, aps, shots=(), grammar_in_prompt=False, constrained=True):
        key = (nl, tuple(aps), tuple(shots), grammar_in_prompt, constrained)
        if key not in self._memo:  # one request at a time: keep only the latest
            self._memo = {key: self.translator.translate(nl, aps, shots, grammar_in_prompt,
                                                         constrained)}
        return self._memo[key]


def _map(trials: Sequence[Trial], config: Exp2Config, n_jobs: int, translator):
    if translator is not None or n_jobs == 1:
        for t in trials:
            yield run_trial(t, config, translator)
        return
    from joblib import Parallel, delayed

    yield from Parallel(n_jobs=n_jobs, return_as="generator")(
        delayed(run_trial)(t, config) for t in trials)


def _load_rows(path: Path) -> list[dict]:
    if not path.exists():
        return []
    rows = []
    for line in path.read_text().splitlines():
        try:
            rows.append(json.loads(line))
        except json.JSONDecodeError:  # a line cut by an interruption: that trial reruns
            break
    complete = {}
    for r in rows:
        complete.setdefault(r["trial"], []).append(r)
    return [r for t, rs in complete.items() if len(rs) == len(METHODS) for r in rs]


COLUMNS = ("trial", "seed", "method", "delta", "helper", "solve_s", "feasible", "before",
           "tau_help", "tau_new", "wait", "stl", "reason")


def write_csv(rows: list[dict], path: Path) -> None:
    with path.open("w", newline="") as f:
        w = csv.DictWriter(f, COLUMNS, extrasaction="ignore")
        w.writeheader()
        for r in sorted(rows, key=lambda r: (r["trial"], METHODS.index(r["method"]))):
            w.writerow(r)


def _stats(values: list[float]) -> dict:
    if not values:
        return {"mean": None, "std": None, "median": None, "n": 0}
    return {"mean": round(statistics.fmean(values), 4),
            "std": round(statistics.stdev(values), 4) if len(values) > 1 else 0.0,
            "median": statistics.median(values), "n": len(values)}


def summarize(rows: list[dict], config: Exp2Config) -> dict:
    """Per-method statistics of Delta over feasible trials, and the paper's ratios."""
    methods = {}
    for m in METHODS:
        mine = [r for r in rows if r["method"] == m]
        deltas = [r["delta"] for r in mine if r["delta"] is not None]
        times = [r["solve_s"] for r in mine]
        methods[m] = {**_stats(deltas), "infeasible": len(mine) - len(deltas),
                      "solve_s": {"mean": round(statistics.fmean(times), 6) if times else None,
                                  "median": statistics.median(times) if times else None,
                                  "max": max(times, default=None)}}
    ours = methods["ours"]["mean"]

    def pct(num, den):
        return None if num is None or den in (None, 0) else round(100 * num / den, 2)

    comparisons = {}
    if ours is not None:
        for m in ("oracle_ils", "oracle_exact"):
            ref = methods[m]["mean"]
            comparisons[f"ours_vs_{m}"] = {
                "value_pct": pct(None if ref is None else ours - ref, ours),
                "formula": f"(ours - {m}) / ours, as the paper's 'within 18%'"}
        for m in ("b2", "b3"):
            ref = methods[m]["mean"]
            comparisons[f"ours_better_than_{m}"] = {
                "value_pct": pct(None if ref is None else ref - ours, ref),
                "formula": f"({m} - ours) / {m}, over each method's feasible trials"}
    return {"config": asdict(config), "trials": len({r["trial"] for r in rows}),
            "methods": methods, "comparisons": comparisons,
            "paper": {"oracle": 4.49, "ours": 5.47, "ours_better_than_b2_pct": 46,
                      "ours_better_than_b3_pct": 53},
            "replay_of_authors_code": {"oracle": 4.51, "ours": [5.26, 5.61], "b2": 7.98,
                                       "b3": [7.78, 8.63]}}


def plot(rows: list[dict], path: Path) -> None:
    """Box plot of Delta per method, like the paper's Fig. 4."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = {"ours": "Ours", "oracle_ils": "Oracle (ILS)", "oracle_exact": "Oracle (exact)",
              "b2": "B2 (nearest adds)", "b3": "B3 (nearest + re-opt.)"}
    data = [[r["delta"] for r in rows if r["method"] == m and r["delta"] is not None]
            for m in METHODS]
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.boxplot(data, showmeans=True)
    ax.set_xticks(range(1, len(METHODS) + 1), [labels[m] for m in METHODS], rotation=15)
    ax.set_ylabel("time-steps added to the system (Delta)")
    n = len({r["trial"] for r in rows})
    ax.set_title(f"Experiment 2: {n} trials (mean as triangle)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def table(summary: dict) -> str:
    """A Markdown table of the summary beside the paper's and the replay's numbers."""
    paper = {"ours": "5.47", "oracle_ils": "4.49", "oracle_exact": "", "b2": "", "b3": ""}
    replay = {"ours": "5.26-5.61", "oracle_ils": "4.51", "oracle_exact": "", "b2": "7.98",
              "b3": "7.78-8.63"}
    lines = ["| method | mean Delta | std | median | n | infeasible | paper | replay |",
             "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for m in METHODS:
        s = summary["methods"][m]
        mean = "-" if s["mean"] is None else f"{s['mean']:.2f}"
        std = "-" if s["std"] is None else f"{s['std']:.2f}"
        med = "-" if s["median"] is None else f"{s['median']:g}"
        lines.append(f"| {m} | {mean} | {std} | {med} | {s['n']} | {s['infeasible']} | "
                     f"{paper[m]} | {replay[m]} |")
    return "\n".join(lines)

