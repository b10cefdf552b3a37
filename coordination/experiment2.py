"""The paper's Experiment 2: who should move the pallet, and what does it cost?

Per trial (``../shared/specs/experiment2.md``; seeds 3000..3099, drawn as the
authors' code draws them by default, see :mod:`ara.coordination.trials`): an 8x8 grid,
a help site, 6 forklifts, 12 pick-and-place jobs, a makespan cap of 50. The exact
Oracle schedules the 12 jobs once (S_orig); then each method places the help job and
the metric is the time added to the system,

    Delta = (sum of makespans + the requester's wait, after) - (sum of makespans, before)

The requester's wait ends when the helper arrives at the site (``arrival``, the
paper's count) or when the pallet is dropped, one step later (``drop``). Every row
holds both (``delta_arrival``, ``delta``); ``summary.json`` reports both, and the
configured one first. Comparisons between methods use the trials where both are
feasible.

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
import statistics
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path

from ara.coordination.milp import make_solver
from ara.coordination.oracle import Fleet, ILSSettings, exact, ils
from ara.coordination.protocol import (
    REQUEST_WORDINGS,
    Helper,
    HelpRequest,
    choose,
    make_offer,
    request_text,
    template_help_spec,
)
from ara.coordination.trials import (
    INSTANCES,
    PAPER_WORLD,
    Trial,
    closest_robot,
    make_trial,
)
from ara.errors import ConfigError
from ara.stats import describe

METHODS = ("ours", "oracle_ils", "oracle_exact", "b2", "b3")
CAPABILITIES = ("navigate", "report conflicts")
WAITS = ("arrival", "drop")
WORDINGS = ("paper", "all")


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
        if self.instances not in INSTANCES:
            raise ConfigError(f"--instances must be one of {INSTANCES}, got {self.instances!r}")
        if self.wordings not in WORDINGS:
            raise ConfigError(f"--wordings must be one of {WORDINGS}, got {self.wordings!r}")
        if self.wait not in WAITS:
            raise ConfigError(f"--wait must be one of {WAITS}, got {self.wait!r}")
        if self.planner not in ("dp", "milp"):
            raise ConfigError(f"--planner must be dp or milp, got {self.planner!r}")
        if self.llm != "none" and self.planner == "dp":
            raise ConfigError("a translated help request can say anything STL can: plan it "
                              "with --planner milp (the DP handles the template spec only)")


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

    handover = trial.handover_steps

    def row(method: str, delta, helper=None, solve_s=0.0, **extra) -> None:
        rows.append({"trial": trial.index, "seed": trial.seed, "method": method,
                     "delta": delta,
                     "delta_arrival": None if delta is None else delta - handover,
                     "helper": helper, "solve_s": round(solve_s, 6),
                     "feasible": delta is not None, **extra})

    helpers = [Helper(k, trial.starts[k], tuple(trial.jobs[j] for j in route))
               for k, route in enumerate(before.routes)]
    wording = trial.index % len(REQUEST_WORDINGS) if config.wordings == "all" else 0
    request = HelpRequest("requester", trial.site, CAPABILITIES,
                          request_text(trial.site, CAPABILITIES, wording=wording))
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
    if translator is not None:
        rows[-1].update(wording=wording, **_against_template(
            world, trial, request, helpers, offers, {**options, "translator": None}))

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


def _against_template(world, trial: Trial, request: HelpRequest, helpers, offers,
                      options) -> dict:
    """What the helpers' translation did: whether it says the template's spec (Spot),
    how many helpers declined, and the auction's Delta had they planned the template."""
    from ara.grammars import parse
    from ara.grammars.spot_bridge import SpotTimeoutError, equivalent

    stl = next((o.stl for o in offers if o.stl), None)
    help_job = trial.help_job
    try:
        same = stl is not None and equivalent(
            parse(stl), template_help_spec(help_job.pick, help_job.drop, ()), timeout_s=30)
    except SpotTimeoutError:
        same = None
    template = [make_offer(world, h, request, **options) for h in helpers]
    chosen = choose(template)
    return {"template_equivalent": same,
            "declined": sum(not o.can_help for o in offers),
            "delta_template": None if chosen is None else template[chosen].bid}


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
    todo = [make_trial(i, config.seed + i, config.robots, config.jobs, config.instances)
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
    plot(rows, out / "boxplot.png", config.wait)
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


COLUMNS = ("trial", "seed", "method", "delta", "delta_arrival", "helper", "solve_s",
           "feasible", "before", "tau_help", "tau_new", "wait", "stl", "reason", "wording",
           "template_equivalent", "declined", "delta_template")


def write_csv(rows: list[dict], path: Path) -> None:
    with path.open("w", newline="") as f:
        w = csv.DictWriter(f, COLUMNS, extrasaction="ignore")
        w.writeheader()
        for r in sorted(rows, key=lambda r: (r["trial"], METHODS.index(r["method"]))):
            w.writerow(r)


def _delta_key(wait: str) -> str:
    return "delta_arrival" if wait == "arrival" else "delta"


def _method_stats(rows: list[dict], wait: str) -> dict:
    key, methods = _delta_key(wait), {}
    for m in METHODS:
        mine = [r for r in rows if r["method"] == m]
        deltas = [r[key] for r in mine if r[key] is not None]
        times = [r["solve_s"] for r in mine]
        methods[m] = {**describe(deltas), "infeasible": len(mine) - len(deltas),
                      "solve_s": {"mean": round(statistics.fmean(times), 6) if times else None,
                                  "median": statistics.median(times) if times else None,
                                  "max": max(times, default=None)}}
    return methods


def _paired_means(rows: list[dict], wait: str, a: str, b: str) -> tuple[float, float, int]:
    """Mean Delta of methods ``a`` and ``b`` over the trials where both are feasible."""
    key = _delta_key(wait)
    by = {(r["trial"], r["method"]): r[key] for r in rows}
    trials = sorted({r["trial"] for r in rows})
    pairs = [(by.get((t, a)), by.get((t, b))) for t in trials]
    pairs = [(x, y) for x, y in pairs if x is not None and y is not None]
    if not pairs:
        return float("nan"), float("nan"), 0
    return (statistics.fmean(x for x, _ in pairs), statistics.fmean(y for _, y in pairs),
            len(pairs))


def _comparisons(rows: list[dict], wait: str) -> dict:
    """The paper's ratios, each over the trials where both methods are feasible."""
    out = {}
    for m, better in (("oracle_ils", False), ("oracle_exact", False), ("b2", True),
                      ("b3", True)):
        ours, ref, n = _paired_means(rows, wait, "ours", m)
        if better:
            name, value = f"ours_better_than_{m}", (ref - ours) / ref if n and ref else None
            formula = f"({m} - ours) / {m}"
        else:
            name, value = f"ours_vs_{m}", (ours - ref) / ours if n and ours else None
            formula = f"(ours - {m}) / ours, as the paper's 'within 18%'"
        out[name] = {"value_pct": None if value is None else round(100 * value, 2),
                     "trials": n, "formula": formula + ", on the trials where both are feasible"}
    return out


def _translation_summary(rows: list[dict]) -> dict:
    """With an LLM: how often the helpers' formula was the template's, and what the
    wrong ones did to the auction (its Delta against the template's, drop wait)."""
    ours = [r for r in rows if r["method"] == "ours"]
    wrong = [r for r in ours if r.get("template_equivalent") is not True]
    changed = [r for r in wrong if r["delta"] != r.get("delta_template")]
    by_wording: dict[int, list[int]] = {}
    for r in ours:
        by_wording.setdefault(r.get("wording", 0), [0, 0])
        by_wording[r.get("wording", 0)][0] += r.get("template_equivalent") is True
        by_wording[r.get("wording", 0)][1] += 1
    return {"trials": len(ours), "equivalent_to_template": len(ours) - len(wrong),
            "helpers_declined": sum(r.get("declined", 0) for r in ours),
            "wrong_formula_trials": len(wrong),
            "wrong_formula_changed_delta": len(changed),
            "delta_change_when_changed": [
                None if r["delta"] is None else r["delta"] - r["delta_template"]
                for r in changed],
            "by_wording": {str(w): {"equivalent": k, "trials": n}
                           for w, (k, n) in sorted(by_wording.items())}}


def summarize(rows: list[dict], config: Exp2Config) -> dict:
    """Per-method statistics of Delta over feasible trials, with the requester's wait
    counted both ways (``config.wait`` first), and the paper's ratios."""
    by_wait = {w: {"methods": _method_stats(rows, w), "comparisons": _comparisons(rows, w)}
               for w in WAITS}
    chosen = by_wait[config.wait]
    extra = {"translation": _translation_summary(rows)} if config.llm != "none" else {}
    return {"config": asdict(config), "trials": len({r["trial"] for r in rows}),
            "wait": config.wait, "methods": chosen["methods"],
            "comparisons": chosen["comparisons"], "by_wait": by_wait, **extra,
            "paper": {"wait": "arrival", "oracle": 4.49, "ours": 5.47,
                      "ours_better_than_b2_pct": 46, "ours_better_than_b3_pct": 53},
            "replay_of_authors_code": {"wait": "arrival", "oracle": 4.51,
                                       "ours": [5.26, 5.61], "b2": 7.98,
                                       "b3": [7.78, 8.63]}}


def plot(rows: list[dict], path: Path, wait: str = "arrival") -> None:
    """Box plot of Delta per method, like the paper's Fig. 4."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = {"ours": "Ours", "oracle_ils": "Oracle (ILS)", "oracle_exact": "Oracle (exact)",
              "b2": "B2 (nearest adds)", "b3": "B3 (nearest + re-opt.)"}
    key = _delta_key(wait)
    data = [[r[key] for r in rows if r["method"] == m and r[key] is not None]
            for m in METHODS]
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.boxplot(data, showmeans=True)
    ax.set_xticks(range(1, len(METHODS) + 1), [labels[m] for m in METHODS], rotation=15)
    ax.set_ylabel(f"time-steps added to the system (Delta, wait until {wait})")
    n = len({r["trial"] for r in rows})
    ax.set_title(f"Experiment 2: {n} trials (mean as triangle)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def table(summary: dict) -> str:
    """A Markdown table of the summary beside the paper's and the replay's numbers
    (both count the wait until the helper arrives)."""
    paper = {"ours": "5.47", "oracle_ils": "4.49", "oracle_exact": "", "b2": "", "b3": ""}
    replay = {"ours": "5.26-5.61", "oracle_ils": "4.51", "oracle_exact": "", "b2": "7.98",
              "b3": "7.78-8.63"}
    wait = summary.get("wait", "drop")
    note = "" if wait == "arrival" else " (+1 to set beside ours: wait until drop)"
    lines = [f"Delta with the requester's wait counted until {wait}; paper and authors' "
             f"code count until arrival{note}.", "",
             "| method | mean Delta | std | median | n | infeasible | paper | authors' code |",
             "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for m in METHODS:
        s = summary["methods"][m]
        mean = "-" if s["mean"] is None else f"{s['mean']:.2f}"
        std = "-" if s["std"] is None else f"{s['std']:.2f}"
        med = "-" if s["median"] is None else f"{s['median']:g}"
        lines.append(f"| {m} | {mean} | {std} | {med} | {s['n']} | {s['infeasible']} | "
                     f"{paper[m]} | {replay[m]} |")
    return "\n".join(lines)
