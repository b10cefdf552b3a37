"""What an answer leaves out of its request (propositions, stated time bounds, an
order, what should hold, happen or recur) and what it adds that the request never asks
for (nested temporal operators, an order).

A translation that never uses a proposition the user listed, or a number the sentence
states as a bound, is wrong whatever else it says: "reach the dock within 250 steps"
has to put 250 somewhere. On the shipped fine-tune's held-out sets nearly every answer
with such a gap was wrong (docs/model-card.md), so a gap is a cheap, precise signal to
draw more answers (:func:`ara.eval.consistency.translate_repaired`).

The converse is checked for the one slip that needs words to be right: an ``F`` and a
``G`` nested (:mod:`ara.grammars.nesting`). ``G(F(a))`` says "a again and again" and
``F(G(a))`` "a from some point on, for good"; a sentence with no word for either
("Always keep a firm grip on the bottle", "reach the garden") never asks for them,
and ``F(F(a))`` or ``F[10,25](F(a))`` no sentence means. The words that ask for each
pair (:data:`AGAIN_AND_AGAIN_WORDS`, :data:`FOR_GOOD_WORDS`) are the training
realizer's phrasings for them (:mod:`ara.grammars.english`), NL2TL's and their common
synonyms; no reference of the held-out sets or the training mixture's realized
sentences writes a pair its sentence does not ask for, bar a few NL2TL labels.

Order is checked both ways: "in any order" asks for no step after another, so an
answer that writes ``F(a & F(b))`` for it adds one; "then", "after that", "one after
the other" (:data:`SEQUENCE_WORDS`, not the "then" of "if ... then") ask for one, so an
answer that orders nothing in time (:func:`~ara.grammars.nesting.orders_in_time`)
leaves it out.

And what the sentence says in words must hold over time ("always", "keep", "stay",
"never"), happen at some point ("eventually", "at some point") or happen again and
again ("every so often", "repeatedly") the answer has to claim
(:func:`~ara.grammars.nesting.temporal_claims`): ``F[10,20](door_locked)`` for "between
step 10 and step 20, keep the door locked" leaves its ``G`` out (:func:`unclaimed`). The
words (:data:`HOLDS_WORDS`, :data:`HAPPENS_WORDS`, :data:`RECURRING_WORDS`) are those that
say so whatever the rest of the sentence; "whenever", "within" and "during" can mean
either and are not among them.

The checks are one-sided on purpose: an answer with no gap can still be wrong, and a
sentence may state a number that is not a bound ("pick up two boxes"); then no answer
closes the gap and the greedy one is kept.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

from ara.eval.translator import NUMBER_WORDS
from ara.grammars import Formula, atoms, parse, walk
from ara.grammars.ast import interval_of
from ara.grammars.nesting import (
    AGAIN_AND_AGAIN,
    FOR_GOOD,
    HAPPENS,
    HOLDS,
    RESTATED,
    nested_pairs,
    orders_in_time,
    sequenced_steps,
    temporal_claims,
)
from ara.grammars.printer import to_text

_LIFTED = re.compile(r"prop_\d+")
_TIME_WORDS = frozenset("step steps time second seconds minute minutes hour hours unit units "
                        "tick ticks instant instants moment moments".split())

#: Words that ask for ``G(F(a))``: a again and again.
AGAIN_AND_AGAIN_WORDS = re.compile(
    r"\b(again|repeatedly|over and over|time and again|infinitely|often|periodic\w*"
    r"|regularly|every so often|now and then|from time to time|always eventually"
    r"|keep (?:on )?(?:visiting|revisiting|coming|returning|going|checking|patrolling"
    r"|circling|cycling)|back and forth|patrol\w*|alternat\w*|recurr\w*|endless\w*"
    r"|cycl\w*|loop\w*|round|never stops?|continual\w*|routine\w*)\b")
#: Words that ask for ``F(G(a))``: a from some point on, for good.
FOR_GOOD_WORDS = re.compile(
    r"\b(stay|stays|staying|remain|remains|remaining|for good|forever|permanently"
    r"|from (?:then|now|there) on|from (?:that|this|the|some) (?:moment|point|time|step) on"
    r"|eventually always|thereafter|ever after|onwards?|henceforth|indefinitely|in the end"
    r"|ultimately|ends? up|settles?|always|at all times|keep|continu\w*"
    r"|uninterrupted\w*|consecutive\w*|consistently|(?:until|till) the (?:very )?end)\b")
#: Words that order steps: "go to the dock, then charge". A ", then" after a condition
#: ("if a, then b") orders nothing, nor does "sooner or later".
SEQUENCE_WORDS = re.compile(
    r"\b(and then|after that|afterwards?|followed by|one after the other|in (?:that|this) order"
    r"|subsequently|(?<!no )(?<!sooner or )later)\b")
_THEN = re.compile(r"[,;] then\b")
_CONDITION = re.compile(r"\b(if|when|whenever|in case|in the case|in the event|provided"
                        r"|as soon as|once|while|on condition|every ?time|each time)\b")
#: Words that ask for no order between steps.
ANY_ORDER_WORDS = re.compile(
    r"\b(in (?:any|either|whatever|whichever) order|(?:the )?order does not matter"
    r"|regardless of (?:the )?order|no matter (?:the|what|which) order)\b")
#: Words that ask for something to hold over a stretch of time (:data:`HOLDS`). "Stay
#: still" and "stay at the kitchen" name propositions in the realizer's words (``wait``,
#: ``at_kitchen``), and "a or b, never both" is an exclusive or, so those ask nothing.
HOLDS_WORDS = re.compile(
    r"\b(always|at all times|all the time|never(?! both)|at no time|forever|for good|permanently"
    r"|constantly|continuously|throughout|every ?time|each time|keep|keeps|keeping"
    r"|(?:stay|stays|staying)(?! still| at)|remain|remains|remaining|avoid\w*|until|till"
    r"|for (?:the )?(?:next |first |whole |entire )?(?:\d+|[a-z]+ (?:steps|seconds|minutes)))\b")
#: Words that ask for something to happen at some point (:data:`HAPPENS`).
HAPPENS_WORDS = re.compile(
    r"\b(eventually|at some (?:point|time|moment|step)|sooner or later|at least once"
    r"|sometime|someday|ultimately|finally|in the end|at one point"
    r"|(?:by|no later than|before) (?:step|time) \d+)\b")
#: Words that ask for something again and again (:data:`AGAIN_AND_AGAIN`), a strict
#: part of :data:`AGAIN_AND_AGAIN_WORDS`: each of these says it, not only allows it.
RECURRING_WORDS = re.compile(
    r"\b(again and again|repeatedly|over and over|time and again|infinitely often"
    r"|every so often|now and then|from time to time|periodically|regularly"
    r"|keep (?:on )?(?:visiting|revisiting|coming back|returning|going back|checking"
    r"|patrolling|circling|cycling)|patrol\w*|back and forth"
    r"|(?:at least )?once (?:in )?every|in every [\w-]+ (?:window|period|interval))\b")
_ASKING = {HOLDS: HOLDS_WORDS, HAPPENS: HAPPENS_WORDS, AGAIN_AND_AGAIN: RECURRING_WORDS}
_WORDS_FOR = {AGAIN_AND_AGAIN: AGAIN_AND_AGAIN_WORDS, FOR_GOOD: FOR_GOOD_WORDS}
_SAYS = {AGAIN_AND_AGAIN: "again and again", FOR_GOOD: "from some point on, for good",
         RESTATED: "an operator inside the same one"}
_ORDERED = "one step after the other"
_CLAIMS = {HOLDS: "that anything holds over time (G)",
           HAPPENS: "that anything happens at some point (F)",
           AGAIN_AND_AGAIN: "that anything happens again and again (G(F))"}


#: The kinds of gap :class:`Gaps` holds: listed propositions and stated bounds left
#: out, operators nested or steps ordered unasked, an order and claims left out.
KINDS = ("aps", "numbers", "unasked", "order", "claims")


@dataclass(frozen=True)
class Gaps:
    """What an answer leaves out of its request, and what it writes unasked.

    Attributes:
        aps: Listed propositions the answer never uses.
        numbers: Numbers the sentence states that no interval of the answer writes.
        unasked: Subformulas (canonical text) that nest temporal operators or order
            steps as the sentence never asks for (:func:`unasked`).
        unordered: The sentence asks for steps one after the other and the answer
            orders nothing in time.
        claims: What the sentence asks to hold over time, happen at some point or
            happen again and again, and the answer never claims (:func:`unclaimed`).
    """

    aps: tuple[str, ...] = ()
    numbers: tuple[int, ...] = ()
    unasked: tuple[str, ...] = ()
    unordered: bool = False
    claims: tuple[str, ...] = ()

    def __len__(self) -> int:
        return (len(self.aps) + len(self.numbers) + len(self.unasked) + self.unordered
                + len(self.claims))

    def kinds(self) -> list[str]:
        """The kinds of gap held (:data:`KINDS`), in that order."""
        held = {"aps": self.aps, "numbers": self.numbers, "unasked": self.unasked,
                "order": self.unordered, "claims": self.claims}
        return [kind for kind in KINDS if held[kind]]

    def to_json(self) -> dict:
        """The gaps as ``ara translate --json`` writes them: ``left_out`` (``aps``,
        ``numbers``, ``order``, ``claims``) and ``unasked``."""
        return {"left_out": {"aps": list(self.aps), "numbers": list(self.numbers),
                             "order": self.unordered, "claims": list(self.claims)},
                "unasked": list(self.unasked)}

    @classmethod
    def from_json(cls, data: dict) -> Gaps:
        """The gaps of an answer as :meth:`to_json` wrote them (no gap where ``data``
        has no fields for them: an answer that did not parse, or an older file)."""
        left_out = data.get("left_out") or {}
        return cls(tuple(left_out.get("aps", ())), tuple(left_out.get("numbers", ())),
                   tuple(data.get("unasked", ())), left_out.get("order", False),
                   tuple(left_out.get("claims", ())))

    def warning(self, nl: str = "") -> str:
        """What to tell a user whose answer has these gaps: such answers were nearly
        always wrong on the held-out sets, so it should not pass silently. Given the
        sentence ``nl``, the words that ask for a claim left out are quoted."""
        said = []
        if self.aps or self.numbers:
            parts = [*(f"{ap}, a listed proposition," for ap in self.aps),
                     *(f"the bound {n} the sentence states" for n in self.numbers)]
            said.append(f"never uses {' or '.join(parts)}")
        if self.unasked:
            said.append("writes " + " and ".join(
                f"{text} ({_says(text)})" for text in self.unasked)
                + ", which the sentence never asks for")
        if self.unordered:
            said.append("orders nothing in time, where the sentence asks for one step "
                        "after the other")
        if self.claims:
            said.append("never says " + " or ".join(
                _CLAIMS[c] + (f', which "{word}" asks for' if (word := asking_word(nl, c))
                              else ", as the sentence asks")
                for c in self.claims))
        return (f"warning: this answer {'; it also '.join(said)}, so it most likely "
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


def unasked(nl: str, formula: Formula) -> tuple[Formula, ...]:
    """The parts of ``formula`` that ``nl`` never asks for: the nested pairs
    (:func:`~ara.grammars.nesting.nested_pairs`) that restate an operator, ``G(F)`` or
    ``F(G)`` where the sentence has none of the words for it, and steps put one after
    another (:func:`~ara.grammars.nesting.sequenced_steps`) where it says "in any
    order"."""
    text = nl.lower()
    pairs = [node for node, kind in nested_pairs(formula)
             if kind == RESTATED or not _WORDS_FOR[kind].search(text)]
    ordered = list(sequenced_steps(formula)) if ANY_ORDER_WORDS.search(text) else []
    return tuple(pairs + ordered)


def asked_claims(nl: str, aps: Sequence[str] = ()) -> frozenset[str]:
    """What ``nl`` says in words must hold over time, happen at some point, or happen
    again and again (:func:`~ara.grammars.nesting.temporal_claims`); words that name one
    of ``aps`` ("keep apple" for ``keep_apple``) ask for none."""
    text = _unnamed(nl, aps)
    return frozenset(claim for claim, words in _ASKING.items() if words.search(text))


def asking_word(nl: str, claim: str, aps: Sequence[str] = ()) -> str | None:
    """The first words of ``nl`` that ask for ``claim`` ("stay" for :data:`HOLDS`), if
    any, not counting words that name one of ``aps``."""
    found = _ASKING[claim].search(_unnamed(nl, aps))
    return found.group(0) if found else None


def _unnamed(nl: str, aps: Sequence[str]) -> str:
    """``nl`` in lower case with the words that spell a proposition's name blanked."""
    text = nl.lower()
    for ap in aps:
        text = re.sub(rf"\b{re.escape(ap.lower().replace('_', ' '))}\b", " ", text)
    return text


def unclaimed(nl: str, aps: Sequence[str], formula: Formula) -> tuple[str, ...]:
    """What ``nl`` asks to hold, happen or recur that ``formula`` never claims, in the
    order :data:`HOLDS`, :data:`HAPPENS`, :data:`AGAIN_AND_AGAIN`."""
    missing = asked_claims(nl, aps) - temporal_claims(formula)
    return tuple(claim for claim in _ASKING if claim in missing)


def asks_for_order(nl: str) -> bool:
    """Whether ``nl`` puts one step after another in words (:data:`SEQUENCE_WORDS`)."""
    text = nl.lower()
    if ANY_ORDER_WORDS.search(text):
        return False
    if SEQUENCE_WORDS.search(text):
        return True
    then = _THEN.search(text)
    return then is not None and not _CONDITION.search(text[:then.start()])


def _says(text: str) -> str:
    formula = parse(text)
    kinds = [kind for node, kind in nested_pairs(formula) if node == formula]
    return _SAYS[kinds[0]] if kinds else _ORDERED


def gaps(nl: str, aps: Sequence[str], formula: Formula) -> Gaps:
    """What ``formula``, as a translation of ``nl`` over ``aps``, leaves out (an order
    and what should hold, happen or recur too), and what it writes that ``nl`` never
    asks for."""
    used_aps = atoms(formula)
    written = set()
    for node in walk(formula):
        if (iv := interval_of(node)) is not None:
            written |= {iv.lo} | ({iv.hi} if iv.hi is not None else set())
    return Gaps(aps=tuple(ap for ap in aps if ap not in used_aps),
                numbers=tuple(sorted(stated_numbers(nl, aps) - written)),
                unasked=tuple(dict.fromkeys(map(to_text, unasked(nl, formula)))),
                unordered=asks_for_order(nl) and not orders_in_time(formula),
                claims=unclaimed(nl, aps, formula))
