"""Seeded train/test splits of the normalized records, and how much they overlap.

Splits are made over raw rows, so the lifted and grounded records of one row always
fall on the same side.
"""

from __future__ import annotations

import random
from collections import defaultdict

from ara.data.normalize import Record

#: The paper's sizes for the navigation data: 4,500 rows to fine-tune, 3,000 to evaluate.
PAPER_TRAIN_ROWS = 4500
PAPER_TEST_ROWS = 3000


def paper_split(records: list[Record], total_rows: int, seed: int,
                n_train: int = PAPER_TRAIN_ROWS) -> dict[str, list[Record]]:
    """Random row split, as in the paper: the first ``n_train`` of a seeded shuffle train.

    Rows rejected by the normalizer keep their place in the shuffle, so each side's
    row count is the paper's and its record count says how many rows were valid.

    Args:
        records: Normalized records of one raw file.
        total_rows: Number of rows in that file (valid or not).
        seed: Shuffle seed.
        n_train: Rows for training; the rest are for testing.
    """
    order = list(range(total_rows))
    random.Random(seed).shuffle(order)
    train_rows = set(order[:n_train])
    return _by_rows(records, train_rows)


def disjoint_split(records: list[Record], seed: int,
                   test_rows: int = PAPER_TEST_ROWS) -> dict[str, list[Record]]:
    """Split so that no lifted formula occurs on both sides.

    Rows are grouped by their lifted formula; groups are shuffled with ``seed`` and
    moved to test until it holds at least ``test_rows`` rows.
    """
    lifted_of = {r.row: r.stl for r in records if r.form == "lifted"}
    groups: dict[str, list[int]] = defaultdict(list)
    for row, stl in sorted(lifted_of.items()):
        groups[stl].append(row)
    templates = sorted(groups)
    random.Random(seed).shuffle(templates)
    test: set[int] = set()
    for template in templates:
        if len(test) >= test_rows:
            break
        test.update(groups[template])
    return _by_rows(records, set(lifted_of) - test)


def given_split(train: list[Record], test: list[Record]) -> dict[str, list[Record]]:
    """A split fixed by the source files themselves (NL2TL's own train/dev)."""
    return {"train": list(train), "test": list(test)}


def _by_rows(records: list[Record], train_rows: set[int]) -> dict[str, list[Record]]:
    parts: dict[str, list[Record]] = {"train": [], "test": []}
    for r in records:
        parts["train" if r.row in train_rows else "test"].append(r)
    return parts


def overlap_stats(parts: dict[str, list[Record]]) -> dict[str, dict[str, float]]:
    """How much of the test side the training side has already seen, per form.

    Returns:
        ``{form: {"test": n, "formula_seen": fraction, "nl_seen": fraction,
        "pair_seen": fraction}}``, each fraction over that form's test records.
    """
    stats: dict[str, dict[str, float]] = {}
    for form in sorted({r.form for r in parts["test"]}):
        train = [r for r in parts["train"] if r.form == form]
        test = [r for r in parts["test"] if r.form == form]
        formulas, sentences = {r.stl for r in train}, {r.nl for r in train}
        pairs = {(r.nl, r.stl) for r in train}
        n = len(test)
        stats[form] = {
            "test": n,
            "formula_seen": _frac(sum(r.stl in formulas for r in test), n),
            "nl_seen": _frac(sum(r.nl in sentences for r in test), n),
            "pair_seen": _frac(sum((r.nl, r.stl) in pairs for r in test), n),
        }
    return stats


def _frac(k: int, n: int) -> float:
    return round(k / n, 4) if n else 0.0
