"""The shipping rule read off a judge's folder, as `scripts/judge_candidate.sh` leaves it."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

from ara.errors import ConfigError
from ara.eval.verdict import ShippingRule, verdict

REPO = Path(__file__).resolve().parents[2]


def answers(folder: Path, right: int, pairs: int, invalid: int = 0) -> None:
    """A run folder whose first ``right`` of ``pairs`` answers Spot found equivalent."""
    folder.mkdir(parents=True)
    lines = [{"uid": str(i), "equivalent": i < right, "valid": i >= invalid}
             for i in range(pairs)]
    (folder / "samples.jsonl").write_text("".join(json.dumps(x) + "\n" for x in lines))


def judge_folder(root: Path, *, judge=(10, 12), other=(50, 49), help_=(55, 55)) -> Path:
    """Shipped and candidate answers on a judge suite and one other set (its two forms)."""
    for kind in ("greedy", "repair8"):
        answers(root / f"shipped-{kind}/suiteX-grounded", judge[0], 20)
        answers(root / f"candidate-{kind}/suiteX-grounded", judge[1], 20)
    for model, right in zip(("shipped", "candidate"), other, strict=True):
        answers(root / f"{model}-greedy/other-lifted", right // 2, 50)
        answers(root / f"{model}-greedy/other-grounded", right - right // 2, 50)
    for name, n in zip(("help-request-wordings-shipped.json", "help-request-wordings.json"),
                       help_, strict=True):
        (root / name).write_text(json.dumps({"equivalent": n, "requests": 55}))
    return root


def test_a_candidate_better_on_the_judge_and_as_good_elsewhere_ships(tmp_path):
    result = verdict(judge_folder(tmp_path), "suiteX")
    assert result.ships
    judged = {check.name: check for check in result.checks}
    assert judged["suiteX (the judge), greedy"].candidate == "12 of 20 (60.0%)"
    assert judged["other, greedy"].shipped == "50 of 100 (50.0%)"  # both forms summed


def test_a_loss_elsewhere_beyond_the_rule_stops_it_and_says_where(tmp_path):
    result = verdict(judge_folder(tmp_path, other=(50, 48)), "suiteX")
    assert not result.ships
    assert [(c.name, c.why) for c in result.checks if not c.passed] == [
        ("other, greedy", "2.0 points below")]
    assert verdict(tmp_path, "suiteX", ShippingRule(max_drop_points=2)).ships


def test_one_help_request_fewer_stops_it_unless_the_rule_allows_it(tmp_path):
    judge_folder(tmp_path, help_=(55, 54))
    assert not verdict(tmp_path, "suiteX").ships
    assert verdict(tmp_path, "suiteX", ShippingRule(help_misses=1)).ships


def test_what_was_not_measured_fails_rather_than_passes(tmp_path):
    judge_folder(tmp_path)
    (tmp_path / "help-request-wordings-shipped.json").unlink()
    for run in (tmp_path / "candidate-greedy").glob("other-*"):
        (run / "samples.jsonl").unlink()
    failed = {c.name: c.why for c in verdict(tmp_path, "suiteX").checks if not c.passed}
    assert failed == {"other, greedy": "not measured", "help request": "not measured"}


def test_an_invalid_answer_or_a_worse_judge_stops_it(tmp_path):
    judge_folder(tmp_path, judge=(12, 11))
    failed = [c.name for c in verdict(tmp_path, "suiteX").checks if not c.passed]
    assert failed == ["suiteX (the judge), greedy", "suiteX (the judge), repair8"]


def test_a_rule_out_of_range_is_refused():
    with pytest.raises(ConfigError, match="max_drop_points"):
        ShippingRule(max_drop_points=-1)
    with pytest.raises(ConfigError, match="help_misses"):
        ShippingRule(help_misses=-2)


def test_the_verdict_command_writes_what_ship_adapter_refuses_by(tmp_path):
    """`ara eval verdict` writes verdict.json; `scripts/ship_adapter.py` will not ship the
    default file against it without a reason, and says which checks failed."""
    root = judge_folder(tmp_path / "judge", other=(50, 40))
    done = subprocess.run([sys.executable, "-m", "ara.cli", "eval", "verdict", str(root),
                           "--judge", "suiteX"], capture_output=True, text=True, cwd=REPO)
    assert done.returncode == 0, done.stderr
    assert "verdict: does not ship" in done.stdout and "10.0 points below" in done.stdout
    assert json.loads((root / "verdict.json").read_text())["ships"] is False

    export = tmp_path / "export"  # what export_folders needs to find, before any model runs
    for part in ("lora.gguf", "export.json", "run.json", "adapter/adapter_config.json",
                 "adapter/adapter_model.safetensors"):
        (export / part).parent.mkdir(parents=True, exist_ok=True)
        (export / part).write_text("{}")
    (export / "merged-hf").mkdir()
    shipped = subprocess.run([sys.executable, "scripts/ship_adapter.py", str(export),
                              "--verdict", str(root / "verdict.json")],
                             capture_output=True, text=True, cwd=REPO)
    assert shipped.returncode == 2
    assert "does not ship (other, greedy: 10.0 points below)" in shipped.stderr
