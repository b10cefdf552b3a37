"""Experiment 2 end to end on a few trials: files, resume, and the methods' order."""

import csv
import json

import pytest

from ara.coordination.experiment2 import (
    METHODS,
    Exp2Config,
    closest_robot,
    make_trial,
    run,
    run_trial,
)
from ara.errors import ConfigError


def test_trials_are_the_specs_draw():
    t = make_trial(0, 3000)
    assert len(t.starts) == 6 and len(t.jobs) == 12 and t.site not in t.starts
    assert make_trial(0, 3000) == t and make_trial(1, 3001) != t
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
    assert (out / "boxplot.png").stat().st_size > 1000
    with pytest.raises(ConfigError, match="other settings"):
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


def test_a_run_with_the_llm_records_its_model_and_resumes_only_with_it(tmp_path,
                                                                       llama_backend):
    """Tests that run.json names the translator's model (file hashes), and that the
    same folder refuses to continue with another model or none."""
    from ara.eval.translator import Translator

    out = tmp_path / "exp2-llm"
    config = Exp2Config(trials=1, ils_iterations=5, llm="default", planner="milp")
    run(config, out, translator_factory=lambda: Translator(llama_backend), progress=False)
    record = json.loads((out / "run.json").read_text())
    assert record["translator"] == llama_backend.model_id
    with pytest.raises(ConfigError, match="translator gguf:"):
        run(config, out, progress=False)
