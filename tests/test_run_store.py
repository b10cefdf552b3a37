"""Run folders: refusing to overwrite, resuming, cutting a partial line."""

import json

import pytest

from ara.run_store import RunDirError, RunStore, read_samples

META = {"config": {"seed": 0}, "model_id": "m", "data": {"version": "v"},
        "grammar_version": "1"}


def line(uid):
    return {"variant": "F", "shots": 5, "rerun": 0, "uid": uid, "valid": True}


def test_resume_cuts_a_partial_line_and_knows_what_is_done(tmp_path):
    """Tests that a write interrupted mid-line is dropped and the rest kept."""
    with RunStore(tmp_path, META, resume=False) as store:
        store.append(line("a"))
        store.append(line("b"))
    with open(tmp_path / "samples.jsonl", "a") as fh:
        fh.write('{"variant": "F", "sho')  # killed while writing
    with RunStore(tmp_path, META, resume=True) as store:
        assert store.done == {("F", 5, 0, "a"), ("F", 5, 0, "b")}
        store.append(line("c"))
    assert [s["uid"] for s in read_samples(tmp_path)] == ["a", "b", "c"]


def test_an_existing_run_is_not_overwritten(tmp_path):
    """Tests that starting over an earlier run needs --resume."""
    RunStore(tmp_path, META, resume=False).close()
    with pytest.raises(RunDirError, match="pass --resume"):
        RunStore(tmp_path, META, resume=False)


def test_resuming_a_different_run_is_refused(tmp_path):
    """Tests that resume checks config, model and data against run.json."""
    RunStore(tmp_path, META, resume=False).close()
    other = {**META, "model_id": "another"}
    with pytest.raises(RunDirError, match="different model_id"):
        RunStore(tmp_path, other, resume=True)
    assert json.loads((tmp_path / "run.json").read_text())["model_id"] == "m"
