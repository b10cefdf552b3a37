"""The hand-written suites: large enough, well-formed, unambiguous, never trained on."""

from __future__ import annotations

import re

import pytest

from ara.data.handwritten import (
    SUITES,
    WAITING,
    load_suite,
    suite_records,
)
from ara.data.normalize import read_raw
from ara.data.store import RAW_DIR
from ara.grammars import parse
from ara.grammars.spot_bridge import equivalent

#: The least each suite holds: entries, and entries with a time bound.
SIZES = {"handwritten": (150, 40), "handwritten2": (100, 40), "handwritten3": (60, 15),
         "handwritten4": (150, 60), "handwritten5": (120, 40), "handwritten6": (125, 45),
         "handwritten7": (130, 50), "handwritten8": (135, 55), "handwritten9": (140, 55),
         "handwritten10": (140, 55), "handwritten11": (150, 60),
         "handwritten12": (130, 50)}
#: Each suite's domains: from the fourth on, grounded ones no earlier suite covers.
FIRST_DOMAINS = {"lifted", "navigation", "manipulation", "warehouse"}
DOMAINS = {"handwritten": FIRST_DOMAINS, "handwritten2": FIRST_DOMAINS,
           "handwritten3": FIRST_DOMAINS,
           "handwritten4": {"lifted", "household", "drones", "hospital", "manufacturing",
                            "agriculture"},
           "handwritten5": {"lifted", "restaurant", "construction", "lab", "port", "rover"},
           "handwritten6": {"lifted", "retail", "mining", "marine", "airport", "security"},
           "handwritten7": {"lifted", "energy", "rail", "hotel", "delivery", "forestry"},
           "handwritten8": {"lifted", "aquaculture", "library", "venue", "water", "snow"},
           "handwritten9": {"lifted", "datacenter", "film", "carwash", "zoo", "recycling"},
           "handwritten10": {"lifted", "eldercare", "substation", "themepark", "laundry",
                             "bridge"},
           "handwritten11": {"lifted", "ski", "museum", "brewery", "pool", "parking"},
           "handwritten12": {"lifted", "cleanroom", "refinery", "golf", "space", "rescue"}}


@pytest.fixture(scope="module", params=sorted(SUITES))
def suite(request):
    return request.param, load_suite(SUITES[request.param])


def test_suite_covers_what_the_issue_asks(suite):
    """Tests that each suite is large enough, with time bounds, in both forms and every
    domain."""
    name, entries = suite
    least, least_timed = SIZES[name]
    assert len(entries) >= least
    assert sum("[" in e.stl for e in entries) >= least_timed
    assert {e.form for e in entries} == {"lifted", "grounded"}
    assert {e.domain for e in entries} == DOMAINS[name]


#: The suite written last. A suite's file is pinned by its registered data version
#: (tests/data/test_store.py), so Spot's check of an older one, half a minute in all, can
#: wait for the slow tier; the newest, the one being written, is checked by default.
NEWEST = max(SUITES, key=lambda name: int(name.removeprefix("handwritten") or 1))


@pytest.mark.parametrize("name", [pytest.param(name, marks=[] if name == NEWEST else
                                               [pytest.mark.slow]) for name in sorted(SUITES)])
def test_every_reference_differs_from_the_readings_it_must_not_be_confused_with(name):
    """Tests, with Spot, that no listed confusion is equivalent to its reference (so a
    translator that gives one is counted wrong)."""
    entries = load_suite(SUITES[name])
    undistinguished = [(e.nl, c) for e in entries for c in e.confusions
                       if equivalent(parse(e.stl), parse(c), timeout_s=30)]
    assert undistinguished == []


def _norm(text: str) -> str:
    return re.sub(r"[^a-z0-9_]+", " ", text.lower()).strip()


def test_no_suite_sentence_occurs_in_any_training_source(suite):
    """Tests that no suite is copied from NL2TL: no sentence (case and spacing ignored)
    occurs in any vendored raw file."""
    _, entries = suite
    seen = set()
    for path in RAW_DIR.glob("*.jsonl.gz"):
        for row in read_raw(RAW_DIR, path.name.removesuffix(".gz"))[0]:
            for field in ("sentence", "logic_sentence"):
                if row.get(field):
                    seen.add(_norm(" ".join(row[field])))
    assert [e.nl for e in entries if _norm(e.nl) in seen] == []


def test_suites_are_found_by_file_in_order_and_the_waiting_ones_are_among_them():
    names = list(SUITES)
    assert names[:3] == ["handwritten", "handwritten2", "handwritten3"]
    assert names == sorted(names, key=lambda n: int(n.removeprefix("handwritten") or 1))
    assert all(SUITES[n].name == f"suite{n.removeprefix('handwritten')}.yaml" for n in names)
    assert set(WAITING) <= set(SUITES)


def test_each_suite_repeats_no_sentence_of_an_earlier_one():
    earlier: set[str] = set()
    for path in SUITES.values():  # in the order they were written
        assert [e.nl for e in load_suite(path) if _norm(e.nl) in earlier] == [], path.name
        earlier |= {_norm(e.nl) for e in load_suite(path)}


@pytest.mark.parametrize("split", sorted(SUITES))
def test_records_carry_the_references_propositions_and_form(split):
    """Tests that a record's propositions are its reference's, and prop_N means lifted."""
    records = suite_records(split)
    assert len({r.uid for r in records}) == len(records)
    assert {r.source for r in records} == {split}
    for r in records:
        assert set(r.aps) == {a.name for a in _atoms(r.stl)}
        assert (r.form == "lifted") == all(a.startswith("prop_") for a in r.aps)


def _atoms(stl):
    from ara.grammars.ast import Atom, walk

    return [n for n in walk(parse(stl)) if isinstance(n, Atom)]
