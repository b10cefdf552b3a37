"""Experiment 2 end to end on a few trials: files, resume, and the methods' order."""

import csv
import json

import pytest

from ara.coordination.experiment2 import METHODS, Exp2Config, run, run_trial, table
from ara.coordination.trials import closest_robot, make_trial
from ara.errors import ConfigError
from ara.run_store import RunDirError


@pytest.mark.parametrize(("seed", "site", "starts", "first_jobs", "last_job"), [
    (3000, (6, 7), ((7, 0), (1, 0), (3, 1), (0, 5), (2, 7), (7, 5)),
     [((5, 0), (0, 6)), ((2, 4), (5, 4))], ((7, 7), (1, 6))),
    (3001, (3, 0), ((3, 1), (7, 4), (4, 6), (1, 2), (3, 5), (2, 4)),
     [((2, 2), (2, 0)), ((3, 3), (5, 4))], ((7, 7), (7, 4))),
    (3099, (0, 6), ((0, 7), (3, 7), (5, 2), (3, 7), (0, 7), (3, 3)),
     [((0, 5), (4, 7)), ((3, 6), (7, 1))], ((5, 4), (3, 5))),
])
def test_paper_instances_are_pinned(seed, site, starts, first_jobs, last_job):
    """Tests the authors' draw (re-seeded before the site, the starts and the jobs,
    which come four picks then four drops at a time): any change to it moves these."""
    t = make_trial(0, seed)
    assert (t.site, t.starts) == (site, starts)
    assert [(j.pick, j.drop) for j in t.jobs[:2]] == first_jobs
    assert (t.jobs[-1].pick, t.jobs[-1].drop) == last_job


def test_a_trial_is_the_seeds_draw_and_the_closest_robot_is_nearest_the_site():
    """Tests the spec's trial generator (six robots, twelve jobs, a site no robot
    starts on; the same seed, the same trial), the earlier uniform one, and the robot
    the nearest-robot baselines pick."""
    t = make_trial(0, 3000)
    assert len(t.starts) == 6 and len(t.jobs) == 12 and t.site not in t.starts
    assert make_trial(0, 3000) == t and make_trial(1, 3001) != t
    # the project's earlier generator, one unbroken stream, is still there
    uniform = make_trial(0, 3000, instances="uniform")
    assert uniform != t and uniform.site not in uniform.starts
    with pytest.raises(ConfigError, match="instances must be one of"):
        make_trial(0, 3000, instances="authors")
    near = closest_robot(t)
    assert all(abs(s[0] - t.site[0]) + abs(s[1] - t.site[1])
               >= abs(t.starts[near][0] - t.site[0]) + abs(t.starts[near][1] - t.site[1])
               for s in t.starts)


def test_methods_respect_what_each_can_know():
    """On every trial the exact Oracle is a lower bound of every method; B3 (only the
    pin is forced) is at most B2 (nothing else may move)."""
    config = Exp2Config(trials=1, ils_iterations=10)
    for seed in (3000, 3001, 3002, 3003):
        rows = {r["method"]: r for r in run_trial(make_trial(0, seed), config)}
        assert set(rows) == set(METHODS)
        best = rows["oracle_exact"]["delta"]
        for m in METHODS:
            if rows[m]["delta"] is not None:
                assert rows[m]["delta"] >= best, (seed, m)
        if rows["b2"]["delta"] is not None:
            assert rows["b3"]["delta"] <= rows["b2"]["delta"]


def test_both_waits_are_counted_and_differ_by_the_handover_step():
    """Tests the two waits: until the helper arrives (the paper's) and until the pallet
    is dropped on the neighbouring cell, one step later, for every feasible method."""
    config = Exp2Config(trials=1, ils_iterations=5)
    rows = run_trial(make_trial(0, 3001), config)
    for r in rows:
        if r["feasible"]:
            assert r["delta"] - r["delta_arrival"] == 1, r["method"]
        else:
            assert r["delta_arrival"] is None


def test_run_writes_the_file_contract_and_resumes(tmp_path):
    out = tmp_path / "exp2"
    config = Exp2Config(trials=3, ils_iterations=5)
    first = run(config, out, progress=False)
    lines = (out / "trials.jsonl").read_text().splitlines()
    # an interruption cut the last trial's rows: that trial runs again
    (out / "trials.jsonl").write_text("\n".join(lines[:-2]) + '\n{"trial": 2, "me')
    again = run(config, out, progress=False)

    def deltas(summary):  # solve times differ from run to run; Delta must not
        return {m: {k: v for k, v in s.items() if k != "solve_s"}
                for m, s in summary["methods"].items()}

    assert deltas(again) == deltas(first)
    with open(out / "trials.csv") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 3 * len(METHODS)
    assert {"trial", "seed", "method", "delta", "helper", "solve_s"} <= set(rows[0])
    summary = json.loads((out / "summary.json").read_text())
    for m in METHODS:
        assert set(summary["methods"][m]) >= {"mean", "std", "median", "n"}
    assert summary["wait"] == "arrival"
    assert summary["methods"] == summary["by_wait"]["arrival"]["methods"]
    for m in METHODS:  # the paper's wait is one step shorter on every feasible trial
        arrival, drop = (summary["by_wait"][w]["methods"][m] for w in ("arrival", "drop"))
        if arrival["n"]:
            assert drop["mean"] - arrival["mean"] == pytest.approx(1)
    b2 = summary["comparisons"]["ours_better_than_b2"]
    assert b2["trials"] <= 3 and "both are feasible" in b2["formula"]
    assert "counted until arrival" in table(summary)
    assert (out / "boxplot.png").stat().st_size > 1000
    with pytest.raises(RunDirError, match="different config"):
        run(Exp2Config(trials=4), out, progress=False)


def test_parallel_trials_equal_serial_ones(tmp_path):
    config = Exp2Config(trials=2, ils_iterations=5)
    serial = run(config, tmp_path / "a", n_jobs=1, progress=False)
    parallel = run(config, tmp_path / "b", n_jobs=2, progress=False)
    for m in METHODS:
        assert serial["methods"][m]["mean"] == parallel["methods"][m]["mean"]
        assert serial["methods"][m]["n"] == parallel["methods"][m]["n"]


def test_llm_requests_need_the_milp():
    with pytest.raises(ConfigError, match="--planner milp"):
        Exp2Config(llm="default", planner="dp")


@pytest.mark.parametrize("bad", [{"trials": 0}, {"cap": 0}, {"ils_iterations": -1}])
def test_the_config_checks_its_ranges(bad):
    with pytest.raises(ConfigError, match="cap >= 1"):
        Exp2Config(**bad)
    with pytest.raises(ConfigError, match="--wait must be one of"):
        Exp2Config(wait="pick")
    with pytest.raises(ConfigError, match="--instances must be one of"):
        Exp2Config(instances="random")
    with pytest.raises(ConfigError, match="--wordings must be one of"):
        Exp2Config(wordings="some")


# Two trials of helpers translating with the base model; test_protocol's round trip
# tests the help request in the default tier.
@pytest.mark.slow
def test_a_run_with_the_llm_records_its_model_and_resumes_only_with_it(tmp_path,
                                                                       llama_backend):
    """Tests that run.json names the translator's model (file hashes), that the same
    folder refuses to continue with another model or none, and that each trial's
    translation is judged against the template spec and the template's auction."""
    from ara.eval.translate.translator import Translator

    out = tmp_path / "exp2-llm"
    config = Exp2Config(trials=2, ils_iterations=5, llm="default", planner="milp",
                        wordings="all")
    summary = run(config, out, translator_factory=lambda: Translator(llama_backend),
                  progress=False)
    ours = [json.loads(line) for line in (out / "trials.jsonl").read_text().splitlines()
            if json.loads(line)["method"] == "ours"]
    assert [r["wording"] for r in ours] == [0, 1]  # trial i in wording i mod 11
    assert all(r["delta_template"] is not None and 0 <= r["declined"] <= 6 for r in ours)
    seen = summary["translation"]
    assert seen["trials"] == 2
    assert seen["equivalent_to_template"] == sum(r["template_equivalent"] is True for r in ours)
    record = json.loads((out / "run.json").read_text())
    assert record["translator"] == llama_backend.model_id
    with pytest.raises(RunDirError, match="different translator .*'gguf:"):
        run(config, out, progress=False)


def test_the_translation_summary_counts_wrong_formulas_and_their_cost():
    """Tests the LLM record: per wording, how many formulas were the template's, and what
    a wrong one did to Delta, also where one of the two auctions found no helper."""
    from ara.coordination.exp2_report import translation_summary

    rows = [{"method": "ours", "wording": 0, "template_equivalent": True, "delta": 4,
             "delta_template": 4, "declined": 0},
            {"method": "ours", "wording": 1, "template_equivalent": False, "delta": 7,
             "delta_template": 5, "declined": 1},
            {"method": "ours", "wording": 1, "template_equivalent": False, "delta": 6,
             "delta_template": None, "declined": 6},
            {"method": "b2", "delta": 9}]
    seen = translation_summary(rows)
    assert (seen["trials"], seen["equivalent_to_template"], seen["helpers_declined"]) == (3, 1, 7)
    assert seen["delta_change_when_changed"] == [2, None]
    assert seen["by_wording"] == {"0": {"equivalent": 1, "trials": 1},
                                  "1": {"equivalent": 0, "trials": 2}}


def test_helpers_share_one_translation_of_a_request(llama_backend):
    """Tests the translator Experiment 2's helpers share: a repeated generation of the
    current request (greedy or seeded sample) is given again, not recomputed; a new
    request starts afresh; and repair, which helpers run as `ara translate` does, takes
    it as any translator."""
    from ara.coordination.experiment2 import SharedTranslator
    from ara.eval.translate.backends.base import Sampling
    from ara.eval.translate.checks import gaps
    from ara.eval.translate.repair import RepairConfig, translate_repaired
    from ara.eval.translate.request import Request
    from ara.eval.translate.translator import Translator
    from ara.grammars import parse

    shared = SharedTranslator(Translator(llama_backend))
    nl, aps = "always avoid ( prop_1 )", ("prop_1",)
    first = shared.translate(nl, aps)
    assert shared.translate(nl, aps) is first
    drawn = shared.translate(nl, aps, sampling=Sampling(temperature=0.7, seed=1))
    assert shared.translate(nl, aps, sampling=Sampling(temperature=0.7, seed=1)) is drawn
    other = shared.translate("eventually ( prop_1 )", aps)
    assert other is not first and shared.translate(nl, aps) is not first  # forgotten
    vote = translate_repaired(shared, nl, aps, repair=RepairConfig(2, doubt=0.0))  # gaps only
    assert vote.results[0] is shared.translate(nl, aps)  # repair's greedy call, kept
    # more answers than the greedy one exactly where it leaves part of the request out
    searched = bool(gaps(Request.of(nl, aps), parse(vote.results[0].stl)))
    assert (len(vote.results) > 1) == searched


@pytest.mark.parametrize(("bad", "named"), [({"solver": "cplex"}, "--solver"),
                                            ({"planner": "astar"}, "--planner"),
                                            ({"objective": "fastest"}, "--objective")])
def test_the_config_names_a_choice_it_does_not_know(bad, named):
    """A config read from Python or a run.json is checked as the command line is."""
    with pytest.raises(ConfigError, match=f"{named} must be one of"):
        Exp2Config(**bad)
