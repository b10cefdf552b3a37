"""Two evaluation runs compared answer by answer: what a change fixed and what it broke.

Accuracy alone hides churn: a setting that fixes 16 answers and breaks 14 moves the
figure by two. ``ara eval diff BEFORE AFTER`` pairs the samples of two run folders by
their key (variant, shots, rerun, test pair) and sorts each pair into fixed, broken,
rewritten (both right, or both wrong, with another formula) or the same answer.

Two runs of one variant each (say a C run against an F+C run, or two models' C runs)
are paired by rerun and test pair even when their variants differ. "Right" is the
run's own verdict: Spot-equivalent to the reference.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path

from ara.run_store import RunDirError, read_samples, sample_key

#: Kinds of change, in the order reports list them.
KINDS = ("fixed", "broken", "rewritten_right", "rewritten_wrong")


@dataclass(frozen=True)
class Change:
    """One test pair whose answer differs between the runs."""

    kind: str
    nl: str
    reference: str
    before: str | None
    after: str | None
    key: tuple


@dataclass(frozen=True)
class RunDiff:
    """How the answers of ``after`` differ from those of ``before``.

    Attributes:
        cells: The (variant, shots) cells compared, as ``before -> after`` text.
        paired: Test pairs in both runs.
        right_before, right_after: Of those, how many each run got right.
        same: Pairs answered with the same formula (or invalid in both).
        changes: Every pair whose answer differs, fixed and broken first.
        only_before, only_after: Samples the other run does not have.
    """

    cells: tuple[str, ...]
    paired: int
    right_before: int
    right_after: int
    same: int
    changes: tuple[Change, ...]
    only_before: int
    only_after: int
    counts: dict[str, int] = field(init=False)

    def __post_init__(self) -> None:
        counts = {kind: sum(c.kind == kind for c in self.changes) for kind in KINDS}
        object.__setattr__(self, "counts", counts)

    def to_dict(self) -> dict:
        data = asdict(self)
        data["changes"] = [{k: v for k, v in asdict(c).items() if k != "key"}
                           for c in self.changes]
        return data


def _right(sample: dict) -> bool:
    return sample.get("equivalent") is True


def _answer(sample: dict) -> str | None:
    return sample["stl"] if sample.get("valid") else None


def _cell(sample: dict) -> str:
    return f"{sample['variant']}@{sample['shots']}"


def diff_samples(before: Sequence[dict], after: Sequence[dict]) -> RunDiff:
    """Pair two runs' samples and sort every pair by how its answer changed.

    Raises:
        RunDirError: If the runs share no test pair (other data, or several variants
            in one run that the other does not have).
    """
    cells_before = sorted({_cell(s) for s in before})
    cells_after = sorted({_cell(s) for s in after})

    def key(sample: dict) -> tuple:
        if len(cells_before) == 1 and len(cells_after) == 1:
            return sample["rerun"], sample["uid"]  # one cell each: any two variants
        return sample_key(sample)

    old = {key(s): s for s in before}
    new = {key(s): s for s in after}
    shared = [k for k in old if k in new]
    if not shared:
        raise RunDirError(
            f"the runs share no test pair (cells {', '.join(cells_before)} against "
            f"{', '.join(cells_after)}): compare runs on the same data, with one variant "
            "each or the same variants")
    changes, same = [], 0
    for k in shared:
        a, b = old[k], new[k]
        if _answer(a) == _answer(b):
            same += 1
            continue
        kind = {(False, True): "fixed", (True, False): "broken", (True, True):
                "rewritten_right", (False, False): "rewritten_wrong"}[(_right(a), _right(b))]
        changes.append(Change(kind, b["nl"], b["reference"], _answer(a), _answer(b), k))
    changes.sort(key=lambda c: (KINDS.index(c.kind), c.key))
    cells = (f"{', '.join(cells_before)} -> {', '.join(cells_after)}",)
    return RunDiff(cells, len(shared), sum(_right(old[k]) for k in shared),
                   sum(_right(new[k]) for k in shared), same, tuple(changes),
                   len(old) - len(shared), len(new) - len(shared))


def diff_runs(before: Path, after: Path) -> RunDiff:
    """:func:`diff_samples` on two run folders (``samples.jsonl`` each)."""
    return diff_samples(read_samples(before), read_samples(after))


def diff_markdown(diff: dict, show: int = 10) -> str:
    """Counts, then up to ``show`` pairs of each kind (``diff`` as :meth:`RunDiff.to_dict`)."""
    n = diff["paired"]
    lines = [f"Cells {'; '.join(diff['cells'])}; {n} test pairs in both runs"
             + (f" ({diff['only_before']} only before, {diff['only_after']} only after)"
                if diff["only_before"] or diff["only_after"] else "") + ".",
             "", "| | pairs |", "|---|---:|",
             f"| right before | {diff['right_before']} of {n} |",
             f"| right after | {diff['right_after']} of {n} |"]
    lines += [f"| {kind.replace('_', ' ')} | {diff['counts'][kind]} |" for kind in KINDS]
    lines.append(f"| same answer | {diff['same']} |")
    for kind in KINDS:
        shown = [c for c in diff["changes"] if c["kind"] == kind][:show]
        if not shown:
            continue
        lines += ["", f"{kind.replace('_', ' ').capitalize()}:", ""]
        lines += [f"- {c['nl']}  \n  `{c['before']}` -> `{c['after']}` (reference "
                  f"`{c['reference']}`)" for c in shown]
        more = diff["counts"][kind] - len(shown)
        if more > 0:
            lines.append(f"- ... {more} more (--show, or --json for all)")
    return "\n".join(lines)
