"""A request analysed once: everything the grammar and the checks of an answer read
from its sentence (:mod:`ara.grammars.cues`), so that no candidate answer re-reads it.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache

from ara.grammars.cues import (
    ANY_ORDER_WORDS,
    CLAIM_WORDS,
    NEGATION_WORDS,
    NESTING_WORDS,
    NUMBER_WORDS,
    TIME_WORDS,
    condition_clauses,
    says_in_order,
)

_LIFTED = re.compile(r"prop_\d+")


@dataclass(frozen=True)
class Request:
    """One sentence and its propositions, with what its words ask for.

    Attributes:
        nl: The sentence.
        aps: Its propositions, as listed.
        unmentioned: The propositions it never mentions (:func:`mentions`), which a
            request may not list.
        numbers: Every number it writes, in digits or words: the bounds its grammar
            may use (:meth:`~ara.eval.translate.translator.TranslatorConfig.syntax`).
        digits: The numbers it writes in digits.
        stated: The numbers it states as time (:func:`stated_numbers`): the bounds an
            answer has to write.
        claims: What it asks in words to hold, happen or recur, in the order of
            :data:`~ara.grammars.cues.CLAIM_WORDS`; words that name a proposition
            ("keep apple" for ``keep_apple``) ask for none.
        claim_words: The first words asking for each of ``claims``.
        allows: The nested pairs of ``F`` and ``G`` its words allow
            (:data:`~ara.grammars.cues.NESTING_WORDS`).
        ordered: Whether it puts one step after another.
        any_order: Whether it lets its steps come in any order.
        conditions: The propositions it names as a condition (:func:`read_conditions`):
            "whenever the bin is full, empty it" names ``bin_full``.
        affirmed_conditions: Those of ``conditions`` a clause names and does not negate
            (``bin_full`` there; not ``cashier_here`` in "when no cashier is here").
        plain_conditions: Those of ``affirmed_conditions`` the clause names in all the
            words of their names (not ``guard_on`` in "while its guard is off").
        outcomes: Those it names outside its conditions, where it has any (``empty_bin``
            there); a proposition it names in neither way is in neither.
    """

    nl: str
    aps: tuple[str, ...]
    unmentioned: tuple[str, ...] = ()
    numbers: frozenset[int] = frozenset()
    digits: frozenset[int] = frozenset()
    stated: frozenset[int] = frozenset()
    claims: tuple[str, ...] = ()
    claim_words: tuple[str, ...] = ()
    allows: frozenset[str] = frozenset()
    ordered: bool = False
    any_order: bool = False
    conditions: frozenset[str] = frozenset()
    affirmed_conditions: frozenset[str] = frozenset()
    plain_conditions: frozenset[str] = frozenset()
    outcomes: frozenset[str] = frozenset()

    @classmethod
    def of(cls, nl: str, aps: Sequence[str]) -> Request:
        """``nl`` over ``aps`` analysed; the same request again is not read twice (the
        translator's grammar and scoring ask for it per candidate answer)."""
        return _analysed(nl, tuple(aps))

    def asking_word(self, claim: str) -> str | None:
        """The first words that ask for ``claim`` ("stay" for ``G``), if it is asked."""
        return dict(zip(self.claims, self.claim_words, strict=True)).get(claim)


@lru_cache(maxsize=1024)
def _analysed(nl: str, aps: tuple[str, ...]) -> Request:
    # The nesting and order cues read the sentence whole, the claims with the words of a
    # name blanked, the numbers with whole names blanked: each as its lists were tuned.
    text, unnamed = nl.lower(), _unnamed(nl, aps)
    found = [(claim, m.group(0)) for claim, words in CLAIM_WORDS.items()
             if (m := words.search(unnamed))]
    conditions, affirmed, plain, outcomes = read_conditions(nl, aps)
    return Request(nl=nl, aps=aps, unmentioned=tuple(ap for ap in aps if not mentions(nl, ap)),
                   numbers=frozenset(written_numbers(nl)), digits=digits_of(nl),
                   stated=stated_numbers(nl, aps),
                   claims=tuple(claim for claim, _ in found),
                   claim_words=tuple(word for _, word in found),
                   allows=frozenset(pair for pair, words in NESTING_WORDS.items()
                                    if words.search(text)),
                   ordered=says_in_order(text),
                   any_order=ANY_ORDER_WORDS.search(text) is not None,
                   conditions=conditions, affirmed_conditions=affirmed,
                   plain_conditions=plain, outcomes=outcomes)


_STOPWORDS = frozenset({"the", "and", "for", "not", "with", "from", "into", "onto"})
#: Short words of a name that say which state it is (``guard_on``, ``arm_up``): a
#: clause in other words ("its guard is off") may name the opposite state.
_STATE_WORDS = frozenset({"on", "off", "up", "down", "out"})


def _name_words(ap: str) -> list[str]:
    """The words of a proposition's name that can identify it: 3+ letters, not a stopword."""
    return [w for w in ap.lower().split("_") if len(w) >= 3 and w not in _STOPWORDS]


def mentions(nl: str, ap: str) -> bool:
    """Whether ``nl`` mentions proposition ``ap``: its name, or a word of it (3+ letters)."""
    text = nl.lower()
    if re.search(rf"\b{re.escape(ap.lower())}\b", text):
        return True
    return any(w in text for w in _name_words(ap))


def read_conditions(nl: str, aps: Sequence[str]) -> tuple[frozenset[str], ...]:
    """What ``nl`` names as conditions, affirmed, plainly, and as outcomes: the
    :class:`Request` attributes ``conditions``, ``affirmed_conditions``,
    ``plain_conditions`` and ``outcomes``.

    A proposition belongs to the condition clauses
    (:func:`~ara.grammars.cues.condition_clauses`) where more of its name's words stand
    in them than elsewhere, to the outcomes where fewer: ``prop_2`` and ``prop_1`` in
    "whenever ( prop_2 ) holds, ( prop_1 )"; ``bag_flagged`` and ``bag_at_inspection_room``
    in "if security flags a bag, take it to the inspection room". Words match by stem."""
    text = nl.lower()
    spans = condition_clauses(text)
    if not spans:
        return frozenset(), frozenset(), frozenset(), frozenset()
    clauses = [text[a:b] for a, b in spans]
    starts, ends = zip(*spans, strict=True)
    inside = " ".join(clauses)
    outside = " ".join(text[a:b] for a, b in zip((0, *ends), (*starts, len(text)), strict=True))
    inside_stems, outside_stems = _stems(inside), _stems(outside)
    conditions, affirmed, plain, outcomes = set(), set(), set(), set()
    for ap in aps:
        if _LIFTED.fullmatch(ap):
            here, there = (re.search(rf"\b{ap}\b", t) is not None for t in (inside, outside))
        else:
            stems = [_stem(w) for w in _name_words(ap)]
            here, there = (sum(stem in words for stem in stems)
                           for words in (inside_stems, outside_stems))
        if here > there:
            conditions.add(ap)
            said = [c for c in clauses if _names(c, ap)]
            if said and not any(NEGATION_WORDS.search(c) for c in said):
                affirmed.add(ap)
                plain.update([ap] if any(_names(c, ap, every_word=True) for c in said) else [])
        elif here < there:
            outcomes.add(ap)
    return tuple(map(frozenset, (conditions, affirmed, plain, outcomes)))


def _names(clause: str, ap: str, every_word: bool = False) -> bool:
    """Whether ``clause`` says a word of ``ap``'s name, or with ``every_word`` all of
    them, state words included (``on`` of ``guard_on``)."""
    if _LIFTED.fullmatch(ap):
        return re.search(rf"\b{ap}\b", clause) is not None
    stems = {_stem(w) for w in _name_words(ap)}
    if every_word:
        stems |= {w for w in ap.lower().split("_") if w in _STATE_WORDS}
        return stems <= _stems(clause)
    return bool(stems & _stems(clause))


def _stems(text: str) -> set[str]:
    return {_stem(w) for w in re.findall(r"[a-z0-9]+", text)}


def _stem(word: str) -> str:
    """``word`` without an inflection: "flags" and "flagged" are "flag", "running" and
    "run" "run", "cleaned" and "cleaning" "clean"; "lower" stays apart from "low"."""
    for suffix in ("ing", "ed", "es", "s"):
        if word.endswith(suffix) and len(word) - len(suffix) >= 3 \
                and not word.endswith(("ss", "us")):
            word = word[:-len(suffix)]
            if len(word) > 3 and word[-1] == word[-2] and word[-1] not in "aeiouls":
                word = word[:-1]  # "running", "flagged"
            break
    return word[:-1] if len(word) > 3 and word.endswith("e") else word  # "moving", "move"


def digits_of(nl: str) -> frozenset[int]:
    """The numbers ``nl`` writes in digits."""
    return frozenset(int(n) for n in re.findall(r"\d+", nl))


def written_numbers(nl: str) -> set[int]:
    """The numbers ``nl`` writes, as digits or as words ("ten", "thirty")."""
    words = re.findall(r"[a-z]+", nl.lower())
    return set(digits_of(nl)) | {NUMBER_WORDS[w] for w in words if w in NUMBER_WORDS}


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
        if t in NUMBER_WORDS and TIME_WORDS & set(tokens[max(i - 1, 0):i] + tokens[i + 1:i + 3]):
            numbers.add(NUMBER_WORDS[t])
    return frozenset(numbers - named)


def _unnamed(nl: str, aps: Sequence[str]) -> str:
    """``nl`` in lower case with the words that spell a proposition's name blanked."""
    text = nl.lower()
    for ap in aps:
        text = re.sub(rf"\b{re.escape(ap.lower().replace('_', ' '))}\b", " ", text)
    return text
