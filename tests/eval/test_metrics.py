"""The paper's metrics on hand-made sample sets with known answers."""

import json
import math
from pathlib import Path
from types import SimpleNamespace

import pytest

from ara.data.handwritten import suite_records
from ara.eval.metrics import gap_precision, overhead, score

RESULTS = Path(__file__).parents[2] / "docs" / "results"


def sample(variant, uid, valid, equivalent=None, implies=None, rerun=0, shots=5, ms=100.0):
    """One sample line with only the fields the metrics read."""
    return {"variant": variant, "shots": shots, "rerun": rerun, "uid": uid, "valid": valid,
            "equivalent": equivalent, "implies": implies, "ms": ms}


def by_variant(results):
    return {r["variant"]: r for r in results}


def test_accuracy_uses_only_pairs_valid_under_every_variant():
    """Tests the common-set rule: pair 'c' is invalid under C, so nobody is scored on it."""
    samples = [
        sample("F", "a", True, True), sample("F", "b", True, False, True),
        sample("F", "c", True, True),
        sample("F+C", "a", True, True), sample("F+C", "b", True, True),
        sample("F+C", "c", False),
    ]
    r = by_variant(score(samples))
    assert r["F"]["validity"]["mean"] == 100.0
    assert r["F+C"]["validity"]["mean"] == pytest.approx(200 / 3, abs=1e-3)
    assert r["F"]["accuracy"]["mean"] == 50.0  # a right, b wrong; c not in the common set
    assert r["F+C"]["accuracy"]["mean"] == 100.0
    assert r["F"]["containment"]["mean"] == 100.0  # its one wrong answer implies the reference
    assert r["F"]["common_pairs"]["mean"] == 2.0


def test_reruns_give_mean_and_sample_std():
    """Tests mean +- std over reruns: validity 100% then 50% -> 75 +- 35.36."""
    samples = [sample("F", "a", True, True, rerun=0), sample("F", "b", True, True, rerun=0),
               sample("F", "a", True, True, rerun=1), sample("F", "b", False, rerun=1)]
    (r,) = score(samples)
    assert r["validity"] == {"mean": 75.0, "std": pytest.approx(35.3553, abs=1e-3),
                             "median": 75.0, "n": 2}


def test_undecided_spot_checks_are_counted_not_scored():
    """Tests that a timed-out equivalence neither helps nor hurts accuracy."""
    samples = [sample("F", "a", True, True), sample("F", "b", True, None)]
    (r,) = score(samples)
    assert r["accuracy"]["mean"] == 100.0 and r["undecided"] == 1


def test_containment_without_wrong_answers_is_empty():
    """Tests that containment is undefined (n=0) when every valid answer is right."""
    (r,) = score([sample("F", "a", True, True)])
    assert r["containment"]["n"] == 0 and math.isnan(r["containment"]["mean"])


def test_shot_counts_are_separate_runs():
    """Tests that 5-shot and 20-shot samples are scored apart."""
    samples = [sample("F", "a", True, True, shots=5), sample("F", "a", True, False, shots=20)]
    r = {x["shots"]: x for x in score(samples)}
    assert r[5]["accuracy"]["mean"] == 100.0 and r[20]["accuracy"]["mean"] == 0.0


def test_overhead_pairs_each_constrained_variant_with_its_twin():
    """Tests the latency ratios F+P+C / F+P and C / none (decoding alone)."""
    samples = [sample("F+P", "a", True, True, ms=200.0), sample("F+P+C", "a", True, True, ms=210.0),
               sample("none", "a", True, True, ms=100.0), sample("C", "a", True, True, ms=120.0)]
    assert overhead(score(samples)) == {"F+P+C / F+P @ 5 shots": 1.05,
                                        "C / none @ 5 shots": 1.2}


def test_gap_precision_counts_flagged_references_and_right_or_wrong_answers():
    """Tests gap precision on the hand-written suite's references, which no check flags,
    on the shipped model's stored answers to it, of which three are flagged and all wrong,
    and on a reference flagged, which counts as a right answer repair would act on."""
    assert not any(gap_precision(suite_records("handwritten")).values())
    run = RESULTS / "generalization/shipped-greedy/handwritten-lifted/samples.jsonl"
    answers = [json.loads(line) for line in run.read_text().splitlines()]
    counts = gap_precision(answers=answers)
    assert counts["numbers"] == {"wrong": 1} and counts["unasked"] == {"wrong": 2}
    assert not counts["aps"] + counts["order"] + counts["claims"]
    stay = SimpleNamespace(nl="Go to the dock and stay there.", aps=["at_dock"], stl="F(at_dock)")
    assert gap_precision([stay])["claims"] == {"references": 1}
