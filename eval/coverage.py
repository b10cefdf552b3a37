"""What an answer leaves out of its request: propositions and stated time bounds.

A translation that never uses a proposition the user listed, or a number the sentence
states as a bound, is wrong whatever else it says: "reach the dock within 250 steps"
has to put 250 somewhere. On the shipped fine-tune's held-out sets, 17 of the 18
answers with such a gap were wrong (docs/generalization.md, "Repair"), so a gap is a
cheap, precise signal to draw more answers (:func:`ara.eval.consistency.translate_repaired`).

The check is one-sided on purpose: an answer with no gap can still be wrong, and a
sentence may state a number that is not a bound ("pick up two boxes"); then no answer
closes the gap and the greedy one is kept.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

from ara.eval.translator import NUMBER_WORDS
from ara.grammars import Formula, atoms, walk
from ara.grammars.ast import interval_of

_LIFTED = re.compile(r"prop_\d+")
_TIME_WORDS = frozenset("step steps time second seconds minute minutes hour hours unit units "
                        "tick ticks instant instants moment moments".split())


@dataclass(frozen=True)
class Gaps:
    """What an answer leaves out.

    Attributes:
        aps: Listed propositions the answer never uses.
        numbers: Numbers the sentence states that no interval of the answer writes.
    """

    aps: tuple[str, ...] = ()
    numbers: tuple[int, ...] = ()

    def __len__(self) -> int:
        return len(self.aps) + len(self.numbers)

    def warning(self) -> str:
        """What to tell a user whose answer leaves these out: such answers were nearly
        always wrong on the held-out sets, so it should not pass silently."""
        parts = [*(f"{ap}, a listed proposition," for ap in self.aps),
                 *(f"the bound {n} the sentence states" for n in self.numbers)]
        return (f"warning: this answer never uses {' or '.join(parts)}, so it most likely "
                "misreads the sentence. Read it back with `ara stl explain`; rephrasing the "
                "sentence may help.")


def stated_numbers(nl: str, aps: Sequence[str]) -> frozenset[int]:
    """The numbers ``nl`` states as time: every number in digits, and a number word
    next to a word of time ("ten steps", "step ten", "five more seconds"), less the
    numbers that belong to a proposition (``prop_2`` written out, the 8 of "pallet 8"
    when a proposition is ``deliver_pallet_8``). "At least one of", "one after the
    other" and "the two together" state no bound."""
    text = _LIFTED.sub(" ", nl.lower())
    for ap in aps:
        text = re.sub(rf"\b{re.escape(ap.lower())}\b", " ", text)
    named = {int(n) for ap in aps if not _LIFTED.fullmatch(ap) for n in re.findall(r"\d+", ap)}
    tokens = re.findall(r"[a-z]+|\d+", text)
    numbers = {int(t) for t in tokens if t.isdigit()}
    for i, t in enumerate(tokens):
        if t in NUMBER_WORDS and _TIME_WORDS & set(tokens[max(i - 1, 0):i] + tokens[i + 1:i + 3]):
            numbers.add(NUMBER_WORDS[t])
    return frozenset(numbers - named)


def gaps(nl: str, aps: Sequence[str], formula: Formula) -> Gaps:
    """What ``formula``, as a translation of ``nl`` over ``aps``, leaves out."""
    used_aps = atoms(formula)
    written = set()
    for node in walk(formula):
        if (iv := interval_of(node)) is not None:
            written |= {iv.lo} | ({iv.hi} if iv.hi is not None else set())
    return Gaps(aps=tuple(ap for ap in aps if ap not in used_aps),
                numbers=tuple(sorted(stated_numbers(nl, aps) - written)))
