"""Seeded splits and their overlap statistics."""

import pytest

from ara.data import build_split
from ara.data.normalize import Record
from ara.data.splits import overlap_stats


@pytest.fixture(scope="module")
def paper_parts():
    """The paper split of navi, seed 0, built in memory."""
    return build_split("paper", 0)[0]


@pytest.fixture(scope="module")
def disjoint_parts():
    """The disjoint split of navi, seed 0, built in memory."""
    return build_split("disjoint", 0)[0]


def rows(parts, part):
    return {r.row for r in parts[part]}


def test_paper_split_has_the_papers_row_counts(paper_parts):
    """Tests 4,500 train rows and 3,000 test rows, each less its rejected rows."""
    _, rejected, _ = build_split("paper", 0)
    train, test = rows(paper_parts, "train"), rows(paper_parts, "test")
    n_rejected = len({r.row for r in rejected})
    assert not train & test
    assert len(train) + len(test) + n_rejected == 7500
    assert 4500 - n_rejected <= len(train) <= 4500
    assert 3000 - n_rejected <= len(test) <= 3000


def test_both_forms_of_a_row_fall_on_the_same_side(paper_parts):
    """Tests that a row's lifted and grounded records are never split apart."""
    for part in ("train", "test"):
        forms = {}
        for r in paper_parts[part]:
            forms.setdefault(r.row, set()).add(r.form)
        assert all(f == {"lifted", "grounded"} for f in forms.values())


def test_seed_decides_the_split():
    """Tests that the same seed repeats the split and another seed changes it."""
    a, b, c = (rows(build_split("paper", s)[0], "test") for s in (0, 0, 1))
    assert a == b and a != c


def test_disjoint_split_shares_no_lifted_formula(disjoint_parts):
    """Tests the disjoint split's promise, and that its test side is about 3,000 rows."""
    train = {r.stl for r in disjoint_parts["train"] if r.form == "lifted"}
    test = {r.stl for r in disjoint_parts["test"] if r.form == "lifted"}
    assert not train & test
    assert 3000 <= len(rows(disjoint_parts, "test")) < 3500
    assert overlap_stats(disjoint_parts)["lifted"]["formula_seen"] == 0.0


def test_overlap_stats_count_what_training_has_seen():
    """Tests the statistics on a hand-made split."""
    def rec(uid, nl, stl):
        return Record(uid, nl, stl, ("a",), "navi", "lifted", 0)

    parts = {"train": [rec("1", "go", "F(a)"), rec("2", "stay", "G(a)")],
             "test": [rec("3", "go", "F(a)"), rec("4", "go!", "G(a)"),
                      rec("5", "new", "a"), rec("6", "stay", "F(a)")]}
    stats = overlap_stats(parts)["lifted"]
    assert stats == {"test": 4, "formula_seen": 0.75, "nl_seen": 0.5, "pair_seen": 0.25}
