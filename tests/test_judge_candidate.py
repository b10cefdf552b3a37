"""`scripts/judge_candidate.sh`: what it refuses before spending an hour of answers."""

import subprocess
from pathlib import Path

SCRIPT = Path(__file__).parents[1] / "scripts" / "judge_candidate.sh"


def judge(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([str(SCRIPT), *args], capture_output=True, text=True, timeout=60)


def test_the_judge_must_be_a_suite_kept_blind_for_the_change(tmp_path):
    """Tests that a suite already answered (not in WAITING) cannot judge: its misses may
    have been read, so a candidate could be fitted to it."""
    from ara.data.handwritten import WAITING

    candidate = tmp_path / "lora.gguf"
    candidate.write_bytes(b"")
    done = judge(str(candidate), "handwritten4")
    assert done.returncode == 2 and "not a blind suite waiting" in done.stderr
    assert "handwritten4" not in WAITING


def test_a_missing_candidate_is_named(tmp_path):
    done = judge(str(tmp_path / "lora.gguf"), "handwritten7")
    assert done.returncode == 2 and f"no file {tmp_path / 'lora.gguf'}" in done.stderr
    assert judge().returncode != 0  # and the usage line without arguments
