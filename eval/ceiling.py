"""How much accuracy the data set's own labels leave room for.

NL2TL labels the same sentence differently in places: "don't (prop_1) or (prop_2)" is
``!prop_1 | prop_2`` in five rows and ``!F(prop_1) | prop_2`` in two. A translator
sees only the sentence and its propositions, so it gives one answer to both, and at
most one of the two labels can count as right. This module measures that limit.

Two numbers, for the test records of a split:

- ``oracle``: the best any deterministic translator can score, even one that read the
  test labels: for every distinct input the largest class of equivalent labels.
- ``train_majority``: the score of a translator that answers every input seen in
  training with its most frequent training label (equivalence classes, as above) and
  is right on every unseen input: what a flawless learner of the training side gets.
"""

from __future__ import annotations

from collections import Counter, defaultdict
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from ara.data.normalize import Record
from ara.grammars.spot_bridge import same_meaning

Key = tuple[str, tuple[str, ...]]


@dataclass(frozen=True)
class Conflict:
    """One input whose test labels disagree with each other or with training."""

    nl: str
    test_labels: dict[str, int]
    train_choice: str | None


@dataclass(frozen=True)
class Ceiling:
    """The label ceiling of one test set.

    Attributes:
        records: Test records measured.
        oracle: Records the best deterministic translator gets right.
        train_majority: Records the flawless learner of the training side gets right.
        conflicts: The inputs that cost either number something.
    """

    records: int
    oracle: int
    train_majority: int
    conflicts: tuple[Conflict, ...]

    def to_dict(self) -> dict:
        n = max(1, self.records)
        return {"records": self.records,
                "oracle": self.oracle, "oracle_accuracy": self.oracle / n,
                "train_majority": self.train_majority,
                "train_majority_accuracy": self.train_majority / n,
                "conflicts": [c.__dict__ for c in self.conflicts]}


def _classes(labels: Sequence[str], same: Callable[[str, str], bool]) -> list[list[str]]:
    """Group labels into classes of equivalent formulas (the first label names each)."""
    classes: list[list[str]] = []
    for label in labels:
        for cls in classes:
            if same(cls[0], label):
                cls.append(label)
                break
        else:
            classes.append([label])
    return classes


def spot_equivalent(a: str, b: str, timeout_s: float = 10.0) -> bool:
    """Equal texts, or formulas Spot proves equivalent (an undecided check counts as
    different, which can only lower the ceiling)."""
    return same_meaning(a, b, timeout_s) is True


def label_ceiling(test: Sequence[Record], train: Sequence[Record],
                  same: Callable[[str, str], bool] = spot_equivalent) -> Ceiling:
    """The ceiling of ``test`` for translators of (sentence, propositions).

    Args:
        test: Records to score.
        train: Records a translator learns from (for ``train_majority``).
        same: Whether two formula texts mean the same (default: Spot equivalence).
    """
    by_input: dict[Key, list[str]] = defaultdict(list)
    for r in test:
        by_input[(r.nl, r.aps)].append(r.stl)
    seen: dict[Key, list[str]] = defaultdict(list)
    for r in train:
        seen[(r.nl, r.aps)].append(r.stl)
    oracle = majority = 0
    conflicts = []
    for key, labels in by_input.items():
        classes = _classes(labels, same)
        best = max(len(c) for c in classes)
        oracle += best
        choice = None
        if key in seen:
            # The training side's most frequent class, ties to the first seen.
            choice = max(_classes(seen[key], same), key=len)[0]
            right = sum(len(c) for c in classes if same(c[0], choice))
        else:
            right = best
        majority += right
        if best < len(labels) or right < len(labels):
            conflicts.append(Conflict(key[0], dict(Counter(labels)), choice))
    return Ceiling(len(test), oracle, majority, tuple(conflicts))


def split_ceiling(prepared, form: str, limit: int = 0, seed: int = 0) -> Ceiling:
    """The ceiling of a prepared split's test records, against its train records.

    Args:
        prepared: A :class:`~ara.data.store.PreparedSplit`.
        form: ``lifted`` or ``grounded``.
        limit: Measure only the sample an ablation with this ``limit`` and ``seed``
            scores (0: the whole test side).
        seed: Seed of that sample.
    """
    from ara.eval.harness import AblationConfig, test_sample

    if limit:
        config = AblationConfig(split=prepared.manifest["split"], form=form, limit=limit, seed=seed)
        tests = test_sample(config, prepared)
    else:
        tests = prepared.records("test", form)
    return label_ceiling(tests, prepared.records("train", form))
