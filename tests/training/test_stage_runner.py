"""The staged recipe (`ara train --config` with `stages:`): one command from the base model
to a soup, which a rerun continues and an edit rebuilds from the edited stage on."""

import json
import shutil
from pathlib import Path

import pytest
import yaml

from ara.data import registered_version
from ara.errors import ConfigError
from ara.training.run_folder import whole_checkpoints
from ara.training.stage_runner import recipe_status, run_recipe
from ara.training.stages import StagedRecipe

SHIPPED_RECIPE = Path(__file__).parents[2] / "training" / "configs" / "gemma3_270m_nl2tl.yaml"


def tiny_recipe(model_dir, out, refine_b_seed=2) -> dict:
    """The shipped recipe's shape (a start, two refinements from it, their soup at the
    start's rank) on a tiny model and a few steps."""
    return {
        "out": str(out),
        "defaults": {"base_model": model_dir, "seed": 0, "checkpoint_every": 1,
                     "precision": "fp32",
                     "keep_checkpoints": 1, "eval_pairs": 0,
                     "lora": {"r": 4, "alpha": 8, "dropout": 0.0},
                     "optim": {"lr": 5e-3, "batch_size": 4, "warmup_steps": 0},
                     "data": {"forms": ["lifted"], "limit": 8}},
        "stages": [
            {"name": "start", "train": {"max_steps": 2}},
            {"name": "refine-a", "from": "start", "train": {"seed": 1, "max_steps": 1}},
            {"name": "refine-b", "from": "start",
             "train": {"seed": refine_b_seed, "max_steps": 1}},
            {"name": "soup", "soup": ["refine-a", "refine-b"], "rank": 4},
        ]}


def test_the_shipped_recipe_reads_the_base_model_and_registered_data_alone():
    """Tests the config `ara train` rebuilds `--model finetuned` with: every training stage
    starts from the embedded base model or an earlier stage's adapter under its own
    `out`, on the data version this release registers, and it ends in an export."""
    recipe = StagedRecipe.from_dict(yaml.safe_load(SHIPPED_RECIPE.read_text()))
    kinds = {stage.name: stage.kind for stage in recipe.stages}
    assert [stage.kind for stage in recipe.stages[-2:]] == ["soup", "export"]
    soup = recipe.stages[-2]
    assert len(soup.inputs) >= 2 and all(kinds[name] == "train" for name in soup.inputs)
    for stage in recipe.stages:
        if stage.kind == "train":
            config = recipe.train_config(stage)
            assert config.base_model == "default" and config.data.version is None
            assert config.init_adapter is None or config.init_adapter.startswith(
                str(recipe.out))
    assert recipe.stages[-1].kind == "export" and recipe.stages[-1].inputs == ("soup",)


def test_a_stage_is_what_makes_its_adapter_so_bookkeeping_and_later_stages_leave_it_done():
    """Tests that the held-out check, checkpointing and the stages after a stage do not
    change its fingerprint, so stages trained on a GPU box with the check off and without
    the export count as done on a machine that runs the rest; a training setting does."""
    data = yaml.safe_load(SHIPPED_RECIPE.read_text())
    prints = StagedRecipe.from_dict(data).fingerprints()
    elsewhere = {**data, "defaults": {**data["defaults"], "eval_pairs": 0,
                                      "checkpoint_every": 10},
                 "stages": data["stages"][:-1]}
    assert StagedRecipe.from_dict(elsewhere).fingerprints() == {
        name: value for name, value in prints.items() if name != "export"}
    retuned = {**data, "stages": [{**data["stages"][0], "train": {
        **data["stages"][0]["train"], "max_steps": 941}}, *data["stages"][1:]]}
    assert all(a != b for a, b in zip(StagedRecipe.from_dict(retuned).fingerprints().values(),
                                      prints.values(), strict=True))


def test_precision_is_how_a_stage_is_computed_not_what_it_is():
    """A recipe moved to a machine with other arithmetic (or told bf16 where auto already
    meant it) keeps its stages: only their settings and inputs make them."""
    data = {"out": "runs/x", "stages": [{"name": "a", "train": {}},
                                        {"name": "b", "from": "a", "train": {}}]}
    prints = {precision: StagedRecipe.from_dict({**data, "defaults": {"precision": precision}})
              .fingerprints() for precision in ("auto", "bf16", "fp32")}
    assert prints["auto"] == prints["bf16"] == prints["fp32"] == StagedRecipe.from_dict(
        data).fingerprints()


def test_a_stage_trained_on_the_registered_data_is_stale_once_another_version_is_registered():
    """Tests that `version: null` counts as the version this release registers: pinning
    that very version leaves every stage done, and any other version (what a release that
    registers new data amounts to) makes every stage stale."""
    data = yaml.safe_load(SHIPPED_RECIPE.read_text())
    prints = StagedRecipe.from_dict(data).fingerprints()

    def pinned(version):
        defaults = {**data["defaults"], "data": {**data["defaults"]["data"],
                                                 "version": version}}
        return StagedRecipe.from_dict({**data, "defaults": defaults}).fingerprints()

    assert pinned(registered_version("compositional", 0)) == prints
    assert all(a != b for a, b in zip(pinned("000000000000").values(), prints.values(),
                                      strict=True))


def test_a_stage_is_what_its_files_hold_not_their_names(tmp_path):
    """Tests that a user's pairs file edited, or the adapter a stage warm-starts from
    replaced, makes another stage, though the config reads the same."""
    pairs = tmp_path / "pairs.jsonl"
    pairs.write_text('{"nl": "go to the dock", "stl": "F(go_dock)", "aps": ["go_dock"]}\n')
    warm = tmp_path / "warm"
    warm.mkdir()
    (warm / "adapter_config.json").write_text("{}")
    (warm / "adapter_model.safetensors").write_bytes(b"one")
    recipe = StagedRecipe.from_dict({"out": str(tmp_path / "out"), "defaults": {
        "init_adapter": str(warm), "data": {"pairs": str(pairs)}},
        "stages": [{"name": "a", "train": {}}, {"name": "b", "from": "a", "train": {}}]})
    before = recipe.fingerprints()
    pairs.write_text(pairs.read_text() * 2)
    edited = recipe.fingerprints()
    (warm / "adapter_model.safetensors").write_bytes(b"two")
    assert len({before["a"], edited["a"], recipe.fingerprints()["a"]}) == 3
    assert before["b"] != edited["b"]  # b reads a


@pytest.mark.parametrize("stages, message", [
    ([{"name": "a", "train": {}, "from": "b"}, {"name": "b", "train": {}}],
     "reads 'b', which is not a stage before it"),
    ([{"name": "a", "train": {"out": "elsewhere"}}], "out is set by the recipe"),
    ([{"name": "a", "train": {}}, {"name": "a", "train": {}}], "two stages are named a"),
    ([{"name": "replaced", "train": {}}], "folder for rebuilt stages' old folders"),
    ([{"name": "a", "train": {}}, {"name": "b", "train": {}}, {"name": "s", "soup": "a"}],
     "soup lists the stages it averages"),
    ([{"name": "a", "train": {}}, {"name": "e", "export": ["a"]}], "export names one stage"),
    ([{"name": "a", "train": {}}, {"name": "b", "train": {}},
      {"name": "s", "soup": ["a", "b"], "weights": [1]}], "s: 1 weights for 2 stages"),
    ([{"name": "a", "train": {}}, {"name": "e", "export": "a", "parity": -1}],
     "parity is a number of test pairs"),
    # YAML's yes/true is a bool, which Python counts as the number 1.
    ([{"name": "a", "train": {}}, {"name": "e", "export": "a", "parity": True}],
     "parity is a number of test pairs"),
    ([{"name": "a", "train": {}}, {"name": "b", "train": {}},
      {"name": "s", "soup": ["a", "b"], "weights": [True, 1]}], "weight"),
    ([{"name": "a", "train": {}}, {"name": "s", "soup": ["a"], "rank": True}],
     "a reduced rank is a positive whole number"),
    ([{"name": "a", "train": {}}, {"name": "s", "soup": ["a"]}],
     "a soup needs at least two stages"),
    ([{"name": "a", "train": {}}, {"name": "e", "export": "a"}, {"name": "f", "export": "e"}],
     "reads e, an export"),
    ([{"name": "a", "train": {}, "soup": ["a"]}], "exactly one of train, soup, export"),
    ([{"name": "a", "train": {"optim": {"lr": -1}}}], "optim.lr must be a number > 0"),
    ([{"name": "a", "train": {"lora": {"rank": 4}}}], "unknown key lora.rank"),
])
def test_a_recipe_that_cannot_run_is_refused_before_anything_trains(stages, message):
    with pytest.raises(ConfigError, match=message):
        StagedRecipe.from_dict({"out": "runs/x", "stages": stages})


def test_a_recipe_is_refused_in_several_processes(tmp_path, monkeypatch):
    """Tests the guard against `accelerate launch` of a staged recipe: every process
    would set stages aside, soup and export."""
    monkeypatch.setenv("WORLD_SIZE", "2")
    recipe = StagedRecipe.from_dict({"out": str(tmp_path), "stages": [
        {"name": "a", "train": {}}]})
    with pytest.raises(ConfigError, match="a staged recipe runs in one process"):
        run_recipe(recipe)
    assert not list(tmp_path.iterdir())


def test_one_recipe_at_a_time_trains_in_a_folder(tmp_path):
    """Tests the lock: a second `ara train` on a folder another one holds (a rerun
    started while the first still trains) is refused before it touches anything."""
    from ara.training.run_folder import exclusive

    recipe = StagedRecipe.from_dict({"out": str(tmp_path), "stages": [
        {"name": "a", "train": {}}]})
    with exclusive(tmp_path), pytest.raises(ConfigError, match="another ara train is running"):
        run_recipe(recipe)
    assert [p.name for p in tmp_path.iterdir()] == [".lock"]


def test_status_tells_what_a_rerun_would_do_and_touches_nothing(tmp_path):
    """Tests `ara train --config RECIPE --status` on stage folders written as a run leaves
    them: a stage a live run holds, the same stage once that run is gone (killed before
    its first checkpoint, then after one), and the table and JSON the command prints."""
    from typer.testing import CliRunner

    from ara.cli import app
    from ara.training.run_folder import exclusive, held

    out = tmp_path / "out"
    data = {"out": str(out), "stages": [
        {"name": "a", "train": {"max_steps": 40, "optim": {"grad_accum": 2}}},
        {"name": "b", "from": "a", "train": {"max_steps": 10}},
        {"name": "s", "soup": ["b"], "rank": 4}]}
    recipe = StagedRecipe.from_dict(data)
    fresh = recipe_status(recipe)
    assert [(r["state"], r["steps_total"]) for r in fresh["stages"]] == [
        ("to run", 40), ("runs after a", 10), ("runs after b", None)]
    assert fresh["seconds_per_step"] is None and not out.exists()  # read, nothing made

    a = out / "a"
    a.mkdir(parents=True)
    (a / "stage.json").write_text(json.dumps({"name": "a", "kind": "train", "done": False,
                                              "fingerprint": recipe.fingerprints()["a"]}))
    # 100 records in micro-batches of 8, two a step: 6 steps, under max_steps.
    (a / "run.json").write_text(json.dumps({"data": {
        "train_examples": 100, "version": registered_version("paper", 0)}}))
    (a / "train_log.jsonl").write_text("".join(
        json.dumps({"step": n, "seconds": 2.0}) + "\n" for n in (1, 2, 3)) + '{"step": 4, "se')
    with exclusive(out):
        assert held(out)
        live = recipe_status(recipe)
    assert live["running"] and live["stages"][0] == {
        "name": "a", "kind": "train", "state": "running now", "steps_done": 3,
        "steps_total": 6, "steps_left": 3}
    assert live["seconds_per_step"] == 2.0 and live["hours_left"] == round(13 * 2 / 3600, 2)

    assert not held(out)
    gone = recipe_status(recipe)["stages"][0]
    assert (gone["state"], gone["steps_done"]) == (
        "runs again: it stopped before its first checkpoint", 0)
    (a / "checkpoints" / "step_2").mkdir(parents=True)
    (a / "checkpoints" / "step_2" / "step.json").write_text("{}")
    config = tmp_path / "recipe.yaml"
    config.write_text(yaml.safe_dump(data))
    table = CliRunner().invoke(app, ["train", "--config", str(config), "--status"])
    assert table.exit_code == 0 and "| a | train | 2 / 6 | resumes from step 2 |" in table.output
    as_json = CliRunner().invoke(app, ["train", "--config", str(config), "--status", "--json"])
    assert json.loads(as_json.output)["steps_left"] == 4 + 10
    smoke = CliRunner().invoke(app, ["train", "--config", str(config), "--status",
                                     "--max-steps", "3"])  # another run: a starts over
    assert "| a | train | 0 / 3 | runs again: its settings changed |" in smoke.output
    assert sorted(p.name for p in out.iterdir()) == [".lock", "a"]


def test_one_command_runs_every_stage_and_a_rerun_goes_on_where_it_stopped(
        tiny_gemma_dir, paper_split, tmp_path):
    """Tests the runner end to end on a tiny Gemma 3: interrupted between stages, a rerun
    skips what is done; an edited stage is run again with every stage after it that
    reads it, and nothing else; each stage's wall time and memory are recorded."""
    out = tmp_path / "recipe"
    recipe = StagedRecipe.from_dict(tiny_recipe(tiny_gemma_dir, out))

    def stop_at_refine_a(line):
        if line.startswith("stage refine-a: started"):
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_recipe(recipe, log=stop_at_refine_a)
    assert json.loads((out / "start" / "stage.json").read_text())["done"] is True
    assert not (out / "refine-a").exists()
    # `ara train --status` reads where it stands, changing nothing.
    status = recipe_status(recipe)
    assert [(r["name"], r["state"], r["steps_done"], r["steps_total"])
            for r in status["stages"]] == [
        ("start", "done", 2, 2), ("refine-a", "to run", 0, 1), ("refine-b", "to run", 0, 1),
        ("soup", "runs after refine-a, refine-b", None, None)]
    assert status["steps_left"] == 2 and status["seconds_per_step"] >= 0
    assert not status["running"] and not (out / "refine-a").exists()

    lines: list[str] = []
    record = run_recipe(recipe, log=lines.append)
    assert lines[0] == "stage start: done, skipped"
    assert [line for line in lines if "started" in line] == [
        "stage refine-a: started (train)", "stage refine-b: started (train)",
        "stage soup: started (soup)"]
    stages = record["stages"]
    assert set(stages) == {"start", "refine-a", "refine-b", "soup"}
    assert all(s["wall_s"] >= 0 and s["peak_rss_mb"] > 0 for s in stages.values())
    # A tiny soup can take less than the record's 0.1 s; training never does.
    assert all(stages[name]["wall_s"] >= 0 for name in ("start", "refine-a", "refine-b"))
    assert stages["refine-a"]["result"]["steps"] == 1
    soup = json.loads((out / "soup" / "run.json").read_text())
    assert soup["soup"]["rank"] == 8 and soup["reduced"]["rank"] == 4
    warm = json.loads((out / "refine-b" / "run.json").read_text())["init_adapter"]
    assert warm["path"] == str(out / "start" / "adapter")
    assert json.loads((out / "recipe.json").read_text()) == record

    lines.clear()
    run_recipe(recipe, log=lines.append)
    assert all(line.endswith("done, skipped") for line in lines) and len(lines) == 4

    # A stage killed before its first checkpoint (its run.json written) starts again.
    state = json.loads((out / "refine-b" / "stage.json").read_text())
    (out / "refine-b" / "stage.json").write_text(json.dumps({**state, "done": False}))
    assert recipe_status(recipe)["stages"][2]["state"] == "resumes from step 1"
    for part in ("checkpoints", "adapter"):
        shutil.rmtree(out / "refine-b" / part)
    assert [r["state"] for r in recipe_status(recipe)["stages"]][2:] == [
        "runs again: it stopped before its first checkpoint", "runs again after refine-b"]
    lines.clear()
    run_recipe(recipe, log=lines.append)
    assert "stage refine-b: it stopped before its first checkpoint; rebuilding it" in lines
    assert "stage soup: a stage it reads was rebuilt; rebuilding it" in lines

    # Asking for the held-out check later leaves the stages done, and says they lack it.
    checked = tiny_recipe(tiny_gemma_dir, out)
    checked["defaults"]["eval_pairs"] = 2
    lines.clear()
    run_recipe(StagedRecipe.from_dict(checked), log=lines.append)
    assert lines == [f"stage {name}: done, skipped (trained without the held-out check)"
                     for name in ("start", "refine-a", "refine-b")] + [
        "stage soup: done, skipped"]

    # An edited stage is rebuilt with the stages that read it, and the log says why (here
    # refine-b was also trained on data an earlier release registered); its old folder is
    # kept, since an edit (or a release reading settings anew) must not delete hours.
    soup_before = (out / "soup" / "adapter" / "adapter_model.safetensors").read_bytes()
    run_json = out / "refine-b" / "run.json"
    run = json.loads(run_json.read_text())
    run_json.write_text(json.dumps({**run, "data": {**run["data"], "version": "000000000000"}}))
    edited = StagedRecipe.from_dict(tiny_recipe(tiny_gemma_dir, out, refine_b_seed=3))
    states = [r["state"] for r in recipe_status(edited)["stages"]]
    assert states[:2] == ["done", "done"] and states[3] == "runs again after refine-b"
    assert states[2].startswith("runs again: it was trained on paper version 000000000000")
    lines.clear()
    run_recipe(edited, log=lines.append)
    assert [line for line in lines if "skipped" in line] == [
        "stage start: done, skipped", "stage refine-a: done, skipped"]
    (kept,) = (out / "replaced").iterdir()
    assert [line for line in lines if "rebuilding" in line] == [
        "stage refine-b: it was trained on paper version 000000000000 and this run asks "
        f"for {registered_version('paper', 0)} (to keep it, pin data.version: "
        "000000000000 in the config, where that version is still prepared); rebuilding it "
        f"(the old folder is kept as {kept}; delete it once unneeded)",
        "stage soup: a stage it reads was rebuilt; rebuilding it"]
    assert kept.name.startswith("refine-b-") and json.loads(
        (kept / "run.json").read_text())["data"]["version"] == "000000000000"
    assert (kept / "adapter" / "adapter_model.safetensors").is_file()
    assert "stage refine-b: started (train)" in lines and "stage soup: started (soup)" in lines
    assert (out / "soup" / "adapter" / "adapter_model.safetensors").read_bytes() != soup_before

    # Undoing the edit brings the set-aside stage back instead of training it again.
    undone = StagedRecipe.from_dict(tiny_recipe(tiny_gemma_dir, out))
    assert recipe_status(undone)["stages"][2]["state"] == f"done (brought back from {kept.name})"
    lines.clear()
    run_recipe(StagedRecipe.from_dict(tiny_recipe(tiny_gemma_dir, out)), log=lines.append)
    (edited_folder,) = (out / "replaced").iterdir()  # the seed-3 one now waits there
    assert (f"stage refine-b: brought back from {kept} (made with these settings); the "
            f"folder in its place is kept as {edited_folder}") in lines
    assert "stage refine-b: done, skipped" in lines
    assert not [line for line in lines if line.startswith("stage refine-b: started")]
    assert "stage soup: started (soup)" in lines  # it was the edited one's soup
    assert json.loads((out / "refine-b" / "run.json").read_text())["config"]["seed"] == 2


@pytest.mark.slow  # a recipe in a subprocess, stopped as a scheduler stops it
def test_a_recipe_stopped_with_sigterm_records_its_time_and_goes_on(tiny_gemma_dir, tmp_path):
    """Tests `ara train --config RECIPE` stopped by SIGTERM (a scheduler, `timeout`,
    `kill`): it ends as Ctrl-C does, exit 143 with what to do, the stage's time recorded
    and its log whole; a rerun goes on."""
    import signal
    import subprocess
    import sys
    import time

    out = tmp_path / "recipe"
    recipe = tiny_recipe(tiny_gemma_dir, out)
    recipe["stages"][0]["train"] = {"max_steps": 400, "optim": {"epochs": 200}}
    config = tmp_path / "recipe.yaml"
    config.write_text(yaml.safe_dump(recipe))
    ara = [sys.executable, "-m", "ara.cli", "train", "--config", str(config)]
    # A file, not a pipe: the progress bar would fill a pipe nobody reads yet
    errors = tmp_path / "stderr.txt"
    with open(errors, "w") as sink:
        proc = subprocess.Popen(ara, stdout=subprocess.DEVNULL, stderr=sink)
    log = out / "start" / "train_log.jsonl"
    deadline = time.monotonic() + 300
    while proc.poll() is None and time.monotonic() < deadline and not (
            log.is_file() and log.read_text().count("\n") >= 3):
        time.sleep(0.1)
    assert proc.poll() is None, errors.read_text()  # still training
    proc.send_signal(signal.SIGTERM)
    proc.wait(timeout=120)
    stderr = errors.read_text()
    assert proc.returncode == 143 and "interrupted: rerun the same command" in stderr, stderr
    state = json.loads((out / "start" / "stage.json").read_text())
    assert state["done"] is False and state["sessions"] == 1 and state["wall_s"] >= 0
    steps = [json.loads(line)["step"] for line in log.read_text().splitlines()]  # all whole
    assert steps == list(range(1, len(steps) + 1)) and len(steps) >= 3
    assert whole_checkpoints(out / "start")  # checkpoint_every 1: it goes on from there
