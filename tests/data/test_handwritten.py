"""The hand-written suite: large enough, well-formed, unambiguous, never trained on."""

from __future__ import annotations

import json
import re

import pytest

from ara.data.handwritten import load_suite, suite_records
from ara.data.store import RAW_DIR
from ara.grammars import parse
from ara.grammars.spot_bridge import equivalent


@pytest.fixture(scope="module")
def suite():
    return load_suite()


def test_suite_covers_what_the_issue_asks(suite):
    """Tests that the suite has >= 150 instructions, >= 40 timed, in both forms."""
    assert len(suite) >= 150
    assert sum("[" in e.stl for e in suite) >= 40
    forms = {e.form for e in suite}
    assert forms == {"lifted", "grounded"}
    assert {e.domain for e in suite} == {"lifted", "navigation", "manipulation", "warehouse"}


def test_every_reference_differs_from_the_readings_it_must_not_be_confused_with(suite):
    """Tests, with Spot, that no listed confusion is equivalent to its reference (so a
    translator that gives one is counted wrong)."""
    undistinguished = [(e.nl, c) for e in suite for c in e.confusions
                       if equivalent(parse(e.stl), parse(c), timeout_s=30)]
    assert undistinguished == []


def test_no_suite_sentence_occurs_in_any_training_source(suite):
    """Tests that the suite is not copied from NL2TL: no sentence (case and spacing
    ignored) occurs in any vendored raw file."""
    def norm(text: str) -> str:
        return re.sub(r"[^a-z0-9_]+", " ", text.lower()).strip()

    seen = set()
    for path in RAW_DIR.glob("*.jsonl"):
        for line in path.read_text().splitlines():
            row = json.loads(line)
            for field in ("sentence", "logic_sentence"):
                if row.get(field):
                    seen.add(norm(" ".join(row[field])))
    assert [e.nl for e in suite if norm(e.nl) in seen] == []


def test_records_carry_the_references_propositions_and_form():
    """Tests that a record's propositions are its reference's, and prop_N means lifted."""
    records = suite_records()
    assert len({r.uid for r in records}) == len(records)
    for r in records:
        assert set(r.aps) == {a.name for a in _atoms(r.stl)}
        assert (r.form == "lifted") == all(a.startswith("prop_") for a in r.aps)


def _atoms(stl):
    from ara.grammars.ast import Atom, walk

    return [n for n in walk(parse(stl)) if isinstance(n, Atom)]
