"""The paper's Experiment 2: who should move the pallet, and what does it cost?

Per trial (``docs/experiment2-spec.md``; seeds 3000..3099, drawn as the
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

Each finished trial's rows are appended to ``trials.jsonl`` at once and made durable
together (:class:`~ara.run_store.RunStore`), so an interrupted run resumes where
it stopped; ``trials.csv``, ``summary.json`` and ``boxplot.png`` are
written from it at the end (:mod:`ara.coordination.exp2_report`). The settings are
:class:`~ara.coordination.exp2_config.Exp2Config`, the instances
:mod:`ara.coordination.trials`.
"""

from __future__ import annotations

import json
import time
from collections.abc import Sequence
from dataclasses import asdict
from pathlib import Path

from ara.coordination.exp2_config import (  # noqa: F401 (the experiment's public names)
    CAPABILITIES,
    METHODS,
    WAITS,
    WORDINGS,
    Exp2Config,
)
from ara.coordination.exp2_report import (  # noqa: F401
    COLUMNS,
    plot,
    summarize,
    table,
    write_csv,
)
from ara.coordination.milp import make_solver
from ara.coordination.oracle import Fleet, FleetError, ILSSettings, exact, ils
from ara.coordination.protocol import (
    REQUEST_WORDINGS,
    Helper,
    HelpRequest,
    choose,
    make_offer,
    request_text,
)
from ara.coordination.trials import PAPER_WORLD, Trial, closest_robot, make_trial
from ara.data.help_requests import says_template
from ara.eval.translate.translator import Translator

#: The run folder's row log: one JSON line per (trial, method).
TRIALS = "trials.jsonl"


def run_trial(trial: Trial, config: Exp2Config, translator=None) -> list[dict]:
    """All methods on one trial; one row per method."""
    world = PAPER_WORLD
    solver = make_solver(config.solver)
    started = time.perf_counter()
    before = exact(Fleet(world, trial.starts, trial.jobs, cap=config.cap), solver)
    before_s = time.perf_counter() - started
    if before.status != "optimal":  # Delta is measured from the proven optimum
        raise FleetError(f"trial {trial.index}: the fleet's schedule before the request has "
                         f"no proven optimum ({before.status}) with --solver {config.solver}")
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
        # What they read and why they declined, which a wrong translation explains.
        row("ours", None, None, sum(offer_s), stl=offers[0].stl,
            reason=f"no helper could help ({offers[0].reason})")
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
    stl = next((o.stl for o in offers if o.stl), None)
    help_job = trial.help_job
    same = stl is not None and says_template(stl, help_job.pick, help_job.drop)
    template = [make_offer(world, h, request, **options) for h in helpers]
    chosen = choose(template)
    return {"template_equivalent": same,
            "declined": sum(not o.can_help for o in offers),
            "delta_template": None if chosen is None else template[chosen].bid}


# -- the run --------------------------------------------------------------------------
def run(config: Exp2Config, out: str | Path, n_jobs: int = 1, translator_factory=None,
        progress: bool = True) -> dict:
    """Run (or resume) the experiment into ``out``; returns the summary."""
    from tqdm import tqdm

    from ara.provenance import git_commit
    from ara.run_store import RunStore, read_samples

    out = Path(out)
    # The translator first: its model hash belongs to the run's identity, so a resumed
    # run cannot mix answers of two adapters.
    translator = SharedTranslator(translator_factory()) if translator_factory else None
    meta = {"config": asdict(config),
            "translator": translator.backend.model_id if translator else None,
            "git_commit": git_commit()}
    # Whole trials only: a trial with some of its methods missing (an interruption)
    # runs again rather than sit in front of what is appended next.
    with RunStore(out, meta, resume=True, samples=TRIALS, key=_row_key,
                  identity=("config", "translator"), keep=_whole_trials) as store:
        finished = {trial for trial, _ in store.done}
        todo = [make_trial(i, config.seed + i, config.robots, config.jobs, config.instances)
                for i in range(config.trials) if i not in finished]
        bar = tqdm(total=config.trials, initial=config.trials - len(todo), desc="exp2",
                   unit="trial", disable=not progress)
        for rows in _map(todo, config, n_jobs, translator):
            store.append(*rows)
            bar.update()
        bar.close()
    rows = read_samples(out, TRIALS)
    write_csv(rows, out / "trials.csv")
    summary = summarize(rows, config)
    (out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    plot(rows, out / "boxplot.png", config.wait)
    return summary


class SharedTranslator(Translator):
    """One translator for all simulated helpers of a process.

    Every helper runs the same model and grammar and repairs the same way (seeded
    samples), so they would all get the same formulas for the same request; keeping
    the current request's generations changes no result, only the run time.
    """

    def __init__(self, translator: Translator) -> None:
        super().__init__(translator.backend, translator.config)
        self._memo: dict = {}

    def translate(self, nl, aps, shots=(), grammar_in_prompt=False, constrained=True,
                  sampling=None, require=()):
        key = (nl, tuple(aps), tuple(shots), grammar_in_prompt, constrained, sampling,
               tuple(require))
        if any(k[:2] != key[:2] for k in self._memo):  # one request at a time
            self._memo = {}
        if key not in self._memo:
            self._memo[key] = super().translate(nl, aps, shots, grammar_in_prompt,
                                                constrained, sampling, require)
        return self._memo[key]


def _map(trials: Sequence[Trial], config: Exp2Config, n_jobs: int, translator):
    if translator is not None or n_jobs == 1:
        for t in trials:
            yield run_trial(t, config, translator)
        return
    from joblib import Parallel, delayed

    yield from Parallel(n_jobs=n_jobs, return_as="generator")(
        delayed(run_trial)(t, config) for t in trials)


def _row_key(row: dict) -> tuple:
    return row["trial"], row["method"]


def _whole_trials(rows: list[dict]) -> list[dict]:
    by_trial: dict[int, list[dict]] = {}
    for r in rows:
        by_trial.setdefault(r["trial"], []).append(r)
    return [r for rs in by_trial.values() if len(rs) == len(METHODS) for r in rs]
