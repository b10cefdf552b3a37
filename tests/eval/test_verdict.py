"""The shipping rule read off a judge's folder, as `scripts/judge_candidate.sh` leaves it."""

import importlib.util
import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from ara.coordination.exp2_report import translation_summary
from ara.errors import ConfigError
from ara.eval.verdict import ShippingRule, verdict

REPO = Path(__file__).resolve().parents[2]


def answers(folder: Path, right: int, pairs: int, invalid: int = 0) -> None:
    """A run folder whose first ``right`` of ``pairs`` answers Spot found equivalent."""
    folder.mkdir(parents=True)
    lines = [{"uid": str(i), "equivalent": i < right, "valid": i >= invalid}
             for i in range(pairs)]
    (folder / "samples.jsonl").write_text("".join(json.dumps(x) + "\n" for x in lines))


def experiment2(root: Path, deltas: list[tuple]) -> None:
    """Experiment 2's summary of trials whose (formula equivalent?, Delta, the template's
    Delta) are ``deltas``, summarized as `ara coord exp2` summarizes them."""
    rows = [{"method": "ours", "template_equivalent": same, "delta": delta,
             "delta_template": template, "wording": i % 11, "declined": int(delta is None)}
            for i, (same, delta, template) in enumerate(deltas)]
    (root / "exp2-candidate").mkdir(parents=True, exist_ok=True)
    (root / "exp2-candidate/summary.json").write_text(
        json.dumps({"translation": translation_summary(rows)}))


def judge_folder(root: Path, *, judge=(10, 12), other=(50, 49), help_=(55, 55),
                 auctions=((True, 4, 4), (False, 5, 5))) -> Path:
    """Shipped and candidate answers on a judge suite and one other set (its two forms),
    the help requests and Experiment 2's auctions."""
    for kind in ("greedy", "repair8"):
        answers(root / f"shipped-{kind}/suiteX-grounded", judge[0], 20)
        answers(root / f"candidate-{kind}/suiteX-grounded", judge[1], 20)
    for model, right in zip(("shipped", "candidate"), other, strict=True):
        answers(root / f"{model}-greedy/other-lifted", right // 2, 50)
        answers(root / f"{model}-greedy/other-grounded", right - right // 2, 50)
    for name, n in zip(("help-request-wordings-shipped.json", "help-request-wordings.json"),
                       help_, strict=True):
        (root / name).write_text(json.dumps({"equivalent": n, "requests": 55}))
    experiment2(root, list(auctions))
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
        ("other, greedy", "2.00 points below (2 fewer right)")]
    assert verdict(tmp_path, "suiteX", ShippingRule(max_drop_points=2)).ships


def test_one_help_request_fewer_stops_it_unless_the_rule_allows_it(tmp_path):
    judge_folder(tmp_path, help_=(55, 54))
    assert not verdict(tmp_path, "suiteX").ships
    assert verdict(tmp_path, "suiteX", ShippingRule(help_misses=1)).ships


def test_an_auction_the_translation_changes_or_leaves_unanswered_stops_it(tmp_path):
    """Tests that Experiment 2 judges the help request by its auctions: a formula Spot
    finds unlike the template's passes where the bids are the same, and one trial whose
    request no helper could plan for fails it."""
    judge_folder(tmp_path, auctions=[(False, 4, 4)] * 3)
    assert verdict(tmp_path, "suiteX").ships
    experiment2(tmp_path, [(True, 4, 4), (False, None, 8)])
    failed = {c.name: (c.candidate, c.why) for c in verdict(tmp_path, "suiteX").checks
              if not c.passed}
    assert failed == {"help requests in Experiment 2": (
        "1 of 2 auctions as the template's (1 formulas equivalent)",
        "1 auctions differ or go unanswered")}


def test_what_was_not_measured_fails_rather_than_passes(tmp_path):
    judge_folder(tmp_path)
    (tmp_path / "help-request-wordings-shipped.json").unlink()
    for run in (tmp_path / "candidate-greedy").glob("other-*"):
        (run / "samples.jsonl").unlink()
    shutil.rmtree(tmp_path / "exp2-candidate")
    failed = {c.name: c.why for c in verdict(tmp_path, "suiteX").checks if not c.passed}
    assert failed == {"other, greedy": "not measured", "help request": "not measured",
                      "help requests in Experiment 2": "not measured"}


def test_a_worse_judge_or_an_invalid_answer_stops_it(tmp_path):
    """Tests that the judge allows no answer fewer, greedy or with repair, and that an
    invalid answer the shipped file does not give fails the candidate."""
    judge_folder(tmp_path, judge=(12, 11))
    failed = [c.name for c in verdict(tmp_path, "suiteX").checks if not c.passed]
    assert failed == ["suiteX (the judge), greedy", "suiteX (the judge), repair8"]
    shutil.rmtree(tmp_path / "candidate-repair8/suiteX-grounded")
    answers(tmp_path / "candidate-repair8/suiteX-grounded", 12, 20, invalid=1)
    failed = {c.name: c.why for c in verdict(tmp_path, "suiteX").checks if not c.passed}
    assert failed == {"suiteX (the judge), greedy": "1 fewer right",
                      "invalid answers": "more invalid answers"}


def test_an_interrupted_run_cannot_pass(tmp_path):
    """Tests that a set whose runs answered other pairs (the candidate's stopped after 10
    answers, all right) fails as not measured instead of comparing shares."""
    judge_folder(tmp_path)
    shutil.rmtree(tmp_path / "candidate-greedy/other-grounded")
    answers(tmp_path / "candidate-greedy/other-grounded", 10, 10)
    failed = {c.name: c.why for c in verdict(tmp_path, "suiteX").checks if not c.passed}
    assert failed == {"other, greedy": "not measured: the two runs answered other pairs "
                                       "(one interrupted?)"}


def test_runs_on_an_earlier_data_version_are_not_read(tmp_path):
    judge_folder(tmp_path)
    answers(tmp_path / "candidate-greedy/other-lifted@0123456789ab", 0, 50)
    assert verdict(tmp_path, "suiteX").ships


def test_a_judge_with_no_runs_is_named_with_the_sets_there(tmp_path):
    judge_folder(tmp_path)
    with pytest.raises(ConfigError, match="no runs of suiteY; it has other, suiteX"):
        verdict(tmp_path, "suiteY")
    with pytest.raises(ConfigError, match="no evaluation runs"):
        verdict(tmp_path / "nothing", "suiteX")


def test_a_rule_out_of_range_is_refused():
    with pytest.raises(ConfigError, match="max_drop_points"):
        ShippingRule(max_drop_points=-1)
    with pytest.raises(ConfigError, match="help_misses"):
        ShippingRule(help_misses=-2)


def shipping_script():
    spec = importlib.util.spec_from_file_location("ship_adapter", REPO / "scripts/ship_adapter.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def judged_as(tmp_path: Path, candidate: Path, target: Path, **kwargs) -> Path:
    """The judge's folder of ``candidate`` against ``target``, its verdict written."""
    from ara.data import registered_version
    from ara.provenance import sha256_file

    name = (f"judge-{sha256_file(candidate)[:8]}-{sha256_file(target)[:8]}-"
            f"{registered_version('compositional')}")
    root = judge_folder(tmp_path / name, **kwargs)
    done = subprocess.run([sys.executable, "-m", "ara.cli", "eval", "verdict", str(root),
                           "--judge", "suiteX"], capture_output=True, text=True, cwd=REPO)
    assert done.returncode == 0, done.stderr
    return root / "verdict.json"


def test_a_shipped_file_is_replaced_only_as_its_judge_allows(tmp_path):
    """Tests the gate `scripts/ship_adapter.py` keeps: a verdict of this candidate against
    this shipped file, by the default rule, that says it ships; else only a reason."""
    ship = shipping_script()
    candidate, target = tmp_path / "lora.gguf", tmp_path / "shipped.gguf"
    candidate.write_bytes(b"candidate")
    target.write_bytes(b"shipped")

    passing = judged_as(tmp_path / "a", candidate, target)
    assert ship.judged(candidate, target, passing, None)["problem"] is None
    with pytest.raises(ConfigError, match="no verdict"):
        ship.judged(candidate, target, tmp_path / "none.json", None)
    target.write_bytes(b"shipped since")  # the verdict was against the file before it
    with pytest.raises(ConfigError, match="judged judge-.*, not judge-"):
        ship.judged(candidate, target, passing, None)

    failing = judged_as(tmp_path / "b", candidate, target, other=(50, 40))
    with pytest.raises(ConfigError, match=r"does not ship \(other, greedy: 10.00 points"):
        ship.judged(candidate, target, failing, None)
    kept = ship.judged(candidate, target, failing, "the bids are the template's")
    assert kept["despite"] == "the bids are the template's" and not kept["verdict"]["ships"]

    lenient = json.loads(failing.read_text()) | {"ships": True, "rule": {"max_drop_points": 20,
                                                                          "help_misses": 0}}
    failing.write_text(json.dumps(lenient))
    with pytest.raises(ConfigError, match="another rule than the default"):
        ship.judged(candidate, target, failing, None)


def test_a_recipe_ship_records_the_recipe_that_exported_that_very_file(tmp_path):
    """Tests that the shipped file's record keeps the recipe's record of every stage only
    where its export stage made this file (a rerun since may have exported another)."""
    ship = shipping_script()
    export = tmp_path / "recipe" / "export"
    export.mkdir(parents=True)
    (export / "lora.gguf").write_bytes(b"adapter")
    assert ship.recipe_record(export) is None  # an export outside a recipe

    from ara.provenance import sha256_file

    made = {"stages": {"start": {"result": {"steps": 1721}},
                       "export": {"result": {"files": {"lora.gguf": {
                           "sha256": sha256_file(export / "lora.gguf")}}}}}}
    (export.parent / "recipe.json").write_text(json.dumps(made))
    assert ship.recipe_record(export)["stages"]["start"]["result"]["steps"] == 1721
    (export / "lora.gguf").write_bytes(b"another run's adapter")
    assert ship.recipe_record(export) is None
