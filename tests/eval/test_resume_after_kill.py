"""A real ablation run killed with SIGKILL, then resumed: nothing lost, nothing twice."""

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

ARA = str(Path(sys.executable).with_name("ara"))
ARGS = ["eval", "ablation", "--limit", "4", "--reruns", "1", "--shots", "2",
        "--variants", "F,F+C", "--no-progress"]


def samples(folder):
    return [json.loads(line) for line in (folder / "samples.jsonl").read_text().splitlines()]


def answers(folder):
    """What a run produced, without the timings."""
    return sorted((s["variant"], s["shots"], s["rerun"], s["uid"], s["raw"], s["equivalent"])
                  for s in samples(folder))


@pytest.mark.slow  # four runs of the model; the default tier resumes cut logs in test_run_store
@pytest.mark.usefixtures("embedded_model_path", "paper_split")
def test_resume_after_sigkill_matches_an_uninterrupted_run(tmp_path):
    """Tests resume: kill a real run mid-way, resume it, compare with a clean run."""
    killed, clean = tmp_path / "killed", tmp_path / "clean"
    proc = subprocess.Popen([ARA, *ARGS, "--out", str(killed)], stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 240
    while time.monotonic() < deadline:
        path = killed / "samples.jsonl"
        if path.exists() and len(path.read_text().splitlines()) >= 3:
            break
        time.sleep(0.05)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    done_before = len(samples(killed))
    assert 3 <= done_before < 8, "the run should have been killed part-way"

    out = subprocess.run([ARA, *ARGS, "--out", str(killed)], capture_output=True, text=True)
    assert out.returncode == 2 and "pass --resume" in out.stderr  # no silent overwrite

    resumed = subprocess.run([ARA, *ARGS, "--out", str(killed), "--resume"],
                             capture_output=True, text=True, timeout=600)
    assert resumed.returncode == 0, resumed.stderr
    subprocess.run([ARA, *ARGS, "--out", str(clean)], check=True, capture_output=True,
                   timeout=600)
    keys = [(s["variant"], s["uid"]) for s in samples(killed)]
    assert len(keys) == len(set(keys)) == 8  # 2 variants x 4 pairs, each exactly once
    assert answers(killed) == answers(clean)
    assert (killed / "results.json").exists() and (killed / "plot.png").exists()


def test_score_rebuilds_the_report_without_a_model(tmp_path):
    """Tests `ara eval score` on a hand-written run folder."""
    (tmp_path / "run.json").write_text(json.dumps({
        "config": {"form": "lifted", "reruns": 1}, "model_id": "m", "seed": 0,
        "data": {"split": "paper", "version": "v"}, "grammar_version": "1.0.0"}))
    rows = [{"variant": "F", "shots": 5, "rerun": 0, "uid": str(i), "valid": True,
             "equivalent": i < 3, "implies": True, "ms": 10.0} for i in range(4)]
    (tmp_path / "samples.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    out = subprocess.run([ARA, "eval", "score", str(tmp_path), "--json"], capture_output=True,
                         text=True, check=True)
    (result,) = json.loads(out.stdout)["results"]
    assert result["accuracy"]["mean"] == 75.0 and result["containment"]["mean"] == 100.0
    assert "Table I" in (tmp_path / "tables.md").read_text()


def test_a_missing_model_file_and_an_unknown_variant_are_clear_errors(tmp_path):
    """Tests the messages for a model path that does not exist and a bad variant."""
    out = subprocess.run([ARA, *ARGS, "--out", str(tmp_path / "a"), "--model", "/no/such.gguf"],
                         capture_output=True, text=True)
    assert out.returncode == 2 and "model file not found: /no/such.gguf" in out.stderr
    out = subprocess.run([ARA, *ARGS[:-3], "--variants", "F+Q", "--out", str(tmp_path / "b")],
                         capture_output=True, text=True)
    assert out.returncode == 2 and "letters F (few-shot)" in out.stderr
