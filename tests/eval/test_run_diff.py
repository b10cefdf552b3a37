"""`ara eval diff BEFORE AFTER`: two runs compared answer by answer."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

from ara.eval.run_diff import diff_samples
from ara.run_store import RunDirError

ARA = str(Path(sys.executable).with_name("ara"))

REFERENCES = {"a": "G(!door)", "b": "F(goal)", "c": "F(a & F(b))", "d": "G(F(x))",
              "e": "F(y)"}


def sample(uid: str, stl: str | None, right: bool, variant: str = "C", shots: int = 0,
           rerun: int = 0) -> dict:
    return {"variant": variant, "shots": shots, "rerun": rerun, "uid": uid,
            "nl": f"sentence {uid}", "reference": REFERENCES[uid], "stl": stl,
            "valid": stl is not None, "equivalent": right if stl is not None else None}


BEFORE = [sample("a", "G(!door)", True), sample("b", "G(goal)", False),
          sample("c", "F(a) & F(b)", False), sample("d", "G(F(x))", True),
          sample("e", None, False)]
AFTER = [sample("a", "G(!door)", True), sample("b", "F(goal)", True),
         sample("c", "F(a & b)", False), sample("d", "G(x)", False),
         sample("e", None, False)]


def test_each_pair_is_fixed_broken_rewritten_or_the_same():
    """Tests the sorting of answer pairs, and that an invalid answer in both runs is
    the same answer."""
    diff = diff_samples(BEFORE, AFTER)
    assert (diff.paired, diff.right_before, diff.right_after, diff.same) == (5, 2, 2, 2)
    assert diff.counts == {"fixed": 1, "broken": 1, "rewritten_right": 0,
                           "rewritten_wrong": 1}
    assert [(c.kind, c.before, c.after) for c in diff.changes] == [
        ("fixed", "G(goal)", "F(goal)"), ("broken", "G(F(x))", "G(x)"),
        ("rewritten_wrong", "F(a) & F(b)", "F(a & b)")]


def test_runs_of_one_variant_each_pair_across_variants():
    """Tests that a C run and an F+C run of the same pairs are compared pair by pair,
    while a run with several variants is compared on the variants both have."""
    few_shot = [{**s, "variant": "F+C", "shots": 5} for s in AFTER]
    diff = diff_samples(BEFORE, few_shot)
    assert diff.cells == ("C@0 -> F+C@5",) and diff.paired == 5
    both = diff_samples(BEFORE, [*AFTER, *few_shot])
    assert both.paired == 5 and both.only_after == 5 and both.counts["fixed"] == 1


def test_runs_on_other_data_are_refused():
    """Tests the message when no test pair is in both runs."""
    other = [{**s, "uid": s["uid"] + "-other"} for s in AFTER]
    with pytest.raises(RunDirError, match="share no test pair"):
        diff_samples(BEFORE, other)


def write_run(folder: Path, samples: list[dict]) -> Path:
    folder.mkdir()
    (folder / "samples.jsonl").write_text("".join(json.dumps(s) + "\n" for s in samples))
    return folder


def test_cli_prints_counts_and_pairs_or_json(tmp_path):
    """Tests the command on two run folders: a readable table, and every pair as JSON."""
    before, after = write_run(tmp_path / "a", BEFORE), write_run(tmp_path / "b", AFTER)
    text = subprocess.run([ARA, "eval", "diff", str(before), str(after)],
                          capture_output=True, text=True, check=True).stdout
    assert "| fixed | 1 |" in text and "| same answer | 2 |" in text
    assert "`G(goal)` -> `F(goal)`" in text
    data = json.loads(subprocess.run([ARA, "eval", "diff", str(before), str(after), "--json"],
                                     capture_output=True, text=True, check=True).stdout)
    assert data["counts"]["broken"] == 1 and len(data["changes"]) == 3
    missing = subprocess.run([ARA, "eval", "diff", str(tmp_path), str(after)],
                             capture_output=True, text=True)
    assert missing.returncode == 2 and "not an evaluation run folder" in missing.stderr
