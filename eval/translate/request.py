"""A request analysed once: everything the grammar and the checks of an answer read
from its sentence (:mod:`ara.grammars.cues`), so that no candidate answer re-reads it.
"""

from __future__ import annotations

import os
import re
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache

from ara.grammars.cues import (
    ANY_ORDER_WORDS,
    CLAIM_WORDS,
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
        conditions: The propositions it names as a condition (:func:`conditions_named`):
            "whenever the bin is full, empty it" names ``bin_full``.
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
    return Request(nl=nl, aps=aps, unmentioned=tuple(ap for ap in aps if not mentions(nl, ap)),
                   numbers=frozenset(written_numbers(nl)), digits=digits_of(nl),
                   stated=stated_numbers(nl, aps),
                   claims=tuple(claim for claim, _ in found),
                   claim_words=tuple(word for _, word in found),
                   allows=frozenset(pair for pair, words in NESTING_WORDS.items()
                                    if words.search(text)),
                   ordered=says_in_order(text),
                   any_order=ANY_ORDER_WORDS.search(text) is not None,
                   **dict(zip(("conditions", "outcomes"), conditions_named(nl, aps),
                              strict=True)))


_STOPWORDS = frozenset({"the", "and", "for", "not", "with", "from", "into", "onto"})


def mentions(nl: str, ap: str) -> bool:
    """Whether ``nl`` mentions proposition ``ap``: its name, or a word of it (3+ letters)."""
    text = nl.lower()
    if re.search(rf"\b{re.escape(ap.lower())}\b", text):
        return True
    words = [w for w in ap.lower().split("_") if len(w) >= 3 and w not in _STOPWORDS]
    return any(w in text for w in words)


def conditions_named(nl: str, aps: Sequence[str]) -> tuple[frozenset[str], frozenset[str]]:
    """The propositions of ``aps`` that ``nl`` names in a condition clause
    (:func:`~ara.grammars.cues.condition_clauses`) more than elsewhere, and those it
    names elsewhere more: ``prop_2`` and ``prop_1`` in "whenever ( prop_2 ) holds, (
    prop_1 )"; ``bag_flagged`` and ``bag_at_inspection_room`` in "if security flags a bag,
    take it to the inspection room". A name's words count where a word shares their stem."""
    text = nl.lower()
    spans = condition_clauses(text)
    if not spans:
        return frozenset(), frozenset()
    inside = " ".join(text[a:b] for a, b in spans)
    starts, ends = zip(*spans, strict=True)
    outside = " ".join(text[a:b] for a, b in zip((0, *ends), (*starts, len(text)), strict=True))
    inside_words, outside_words = _words(inside), _words(outside)
    named: tuple[set[str], set[str]] = (set(), set())
    for ap in aps:
        if _LIFTED.fullmatch(ap):
            here, there = (re.search(rf"\b{ap}\b", t) is not None for t in (inside, outside))
        else:
            parts = [w for w in ap.lower().split("_") if len(w) >= 3 and w not in _STOPWORDS]
            here, there = (sum(any(_same_stem(w, t) for t in words) for w in parts)
                           for words in (inside_words, outside_words))
        if here != there:
            named[here < there].add(ap)
    return frozenset(named[0]), frozenset(named[1])


def _words(text: str) -> list[str]:
    return re.findall(r"[a-z0-9]+", text)


def _same_stem(name: str, word: str) -> bool:
    """Whether a word of a proposition's name and a word of a sentence share their stem:
    ``flagged`` and "flags", ``cleaning`` and "cleaned", not ``low`` and "lower"."""
    common = len(os.path.commonprefix([name, word]))
    return common >= min(len(name), 4) and common >= max(len(name), len(word)) - 3


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
