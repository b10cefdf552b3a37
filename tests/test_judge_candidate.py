"""`scripts/judge_candidate.sh`: what it refuses before spending hours of answers, and
what it runs (DRY_RUN prints the commands)."""

import os
import subprocess
from pathlib import Path

import pytest

from ara.data.handwritten import WAITING

SCRIPT = Path(__file__).parents[1] / "scripts" / "judge_candidate.sh"
#: A suite that may judge today: each judged change takes one out of WAITING.
JUDGE = min(WAITING, default=None)
needs_a_waiting_suite = pytest.mark.skipif(JUDGE is None, reason="no suite is in WAITING: "
                                           "write the next blind suite first")


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
    assert all(name in done.stderr for name in WAITING)  # the ones that may judge are named


@needs_a_waiting_suite
def test_a_waiting_suite_judges_both_models_in_a_folder_of_their_own(tmp_path):
    """Tests the plan on a suite in WAITING: both models on the judge, greedy and with
    repair, the diff of each, then the other sets, in a folder named by both files'
    hashes and the data version, so another candidate never resumes this one's runs."""
    from ara.data import registered_version

    candidate = tmp_path / "lora.gguf"
    candidate.write_bytes(b"")
    done = judge(str(candidate), JUDGE, DRY_RUN="1")
    assert done.returncode == 0, done.stderr
    version = registered_version("compositional")
    root = next(w for w in done.stdout.split() if w.startswith("judge-"))
    assert root.startswith("judge-e3b0c442-") and root.rstrip(":").endswith(version)
    plan = [line for line in done.stdout.splitlines() if line.startswith("would run:")]
    assert any(f"lora:{candidate} {root.rstrip(':')}/candidate-repair8 {JUDGE}" in line
               for line in plan)
    assert any("finetuned" in line and f"shipped-greedy {JUDGE}" in line for line in plan)
    assert sum("ara eval diff" in line for line in plan) == 4
    assert any("handwritten9" in line and "compositional timed" in line for line in plan)
    assert any("--model finetuned" in line and "help-request-wordings-shipped.json" in line
               for line in plan)
    assert plan[-1].endswith(f"ara eval verdict runs/generalization/{root.rstrip(':')} "
                             f"--judge {JUDGE}")


def test_a_missing_candidate_is_named(tmp_path):
    done = judge(str(tmp_path / "lora.gguf"), "handwritten12")
    assert done.returncode == 2 and f"no file {tmp_path / 'lora.gguf'}" in done.stderr
    assert judge().returncode != 0  # and the usage line without arguments


@needs_a_waiting_suite
def test_the_shipped_files_committed_answers_are_copied_only_where_they_are_its_own(tmp_path):
    """Tests that the shipped file's greedy answers on the other sets come from
    SHIPPED_ANSWERS where a run there is this very file's, on today's data version and
    the judge's settings, and that a set whose runs are another file's is asked again."""
    import json
    import shutil

    from ara.data import registered_version

    saved = Path(__file__).parents[1] / "docs" / "results" / "generalization" / "shipped-greedy"
    answers = tmp_path / "answers"
    for form in ("lifted", "grounded"):
        shutil.copytree(saved / f"handwritten4-{form}", answers / f"handwritten4-{form}")
        other = shutil.copytree(saved / f"handwritten5-{form}", answers / f"handwritten5-{form}")
        meta = json.loads((other / "run.json").read_text())
        meta["model_id"] = meta["model_id"].rsplit(":", 1)[0] + ":0123456789abcdef"
        (other / "run.json").write_text(json.dumps(meta))
        # The compositional test, sampled (50 a form), as if made on today's version.
        mixed = shutil.copytree(saved / f"compositional-{form}",
                                answers / f"compositional-{form}")
        meta = json.loads((mixed / "run.json").read_text())
        meta["data"]["version"] = registered_version("compositional")
        (mixed / "run.json").write_text(json.dumps(meta))
    candidate = tmp_path / "lora.gguf"
    candidate.write_bytes(b"")
    done = judge(str(candidate), JUDGE, DRY_RUN="1", PAPER="0",
                 SHIPPED_ANSWERS=str(answers))
    assert done.returncode == 0, done.stderr
    copied = [line for line in done.stderr.splitlines() if line.startswith("would copy")]
    assert sorted(line.split()[2].rsplit("/", 1)[1] for line in copied) == [
        "compositional-grounded", "compositional-lifted",
        "handwritten4-grounded", "handwritten4-lifted"]
    shipped = next(line for line in done.stdout.splitlines()
                   if "finetuned" in line and "shipped-greedy handwritten" in line
                   and f"{JUDGE} " not in line and not line.endswith(JUDGE))
    assert "handwritten5" in shipped and "handwritten4 " not in shipped
