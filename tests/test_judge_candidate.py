"""`scripts/judge_candidate.sh`: what it refuses before spending hours of answers, and
what it runs (DRY_RUN prints the commands)."""

import os
import subprocess
from pathlib import Path

SCRIPT = Path(__file__).parents[1] / "scripts" / "judge_candidate.sh"


def judge(*args: str, **env: str) -> subprocess.CompletedProcess:
    return subprocess.run([str(SCRIPT), *args], capture_output=True, text=True, timeout=120,
                          env={**os.environ, **env})


def test_the_judge_must_be_a_suite_kept_blind_for_the_change(tmp_path):
    """Tests that a suite already answered (not in WAITING) cannot judge: its misses may
    have been read, so a candidate could be fitted to it."""
    candidate = tmp_path / "lora.gguf"
    candidate.write_bytes(b"")
    done = judge(str(candidate), "handwritten4", DRY_RUN="1")
    assert done.returncode == 2 and "handwritten4 is not a blind suite waiting" in done.stderr
    assert "handwritten11" in done.stderr  # the ones that may judge are named


def test_a_waiting_suite_judges_both_models_in_a_folder_of_their_own(tmp_path):
    """Tests the plan on a suite in WAITING: both models on the judge, greedy and with
    repair, the diff of each, then the other sets, in a folder named by both files'
    hashes and the data version, so another candidate never resumes this one's runs."""
    from ara.data import registered_version

    candidate = tmp_path / "lora.gguf"
    candidate.write_bytes(b"")
    done = judge(str(candidate), "handwritten11", DRY_RUN="1")
    assert done.returncode == 0, done.stderr
    version = registered_version("compositional")
    root = next(w for w in done.stdout.split() if w.startswith("judge-"))
    assert root.startswith("judge-e3b0c442-") and root.rstrip(":").endswith(version)
    plan = [line for line in done.stdout.splitlines() if line.startswith("would run:")]
    assert any(f"lora:{candidate} {root.rstrip(':')}/candidate-repair8 handwritten11" in line
               for line in plan)
    assert any("finetuned" in line and "shipped-greedy handwritten11" in line for line in plan)
    assert sum("ara eval diff" in line for line in plan) == 4
    assert any("handwritten9" in line and "compositional timed" in line for line in plan)
    assert any("--model finetuned" in line and "help-request-wordings-shipped.json" in line
               for line in plan)
    assert plan[-1].endswith(f"ara eval verdict runs/generalization/{root.rstrip(':')} "
                             "--judge handwritten11")


def test_a_missing_candidate_is_named(tmp_path):
    done = judge(str(tmp_path / "lora.gguf"), "handwritten11")
    assert done.returncode == 2 and f"no file {tmp_path / 'lora.gguf'}" in done.stderr
    assert judge().returncode != 0  # and the usage line without arguments
