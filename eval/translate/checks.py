"""What an answer leaves out of its request, adds unasked or reads the wrong way round,
one registry entry per kind of gap (:data:`CHECKS`): how it is found, which one-edit
mends close it, what the warning and ``--json`` say.

A translation that never uses a listed proposition, or a number the sentence states as
a bound, is wrong whatever else it says: "reach the dock within 250 steps" has to put
250 somewhere. On the shipped fine-tune's held-out sets nearly every answer with a gap
was wrong (docs/model-card.md), so a gap is a cheap, precise signal to look for another
answer (:func:`ara.eval.translate.repair.translate_repaired`). The words each check reads
are :mod:`ara.grammars.cues`.

The checks are one-sided on purpose: an answer with no gap can still be wrong, and a
sentence may state a number that is not a bound ("pick up two boxes"); then no answer
closes the gap and the greedy one is kept.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ara.eval.translate.request import Request
from ara.grammars import Formula, atoms, parse, walk
from ara.grammars.ast import Implies, atoms_read_now, interval_of, signed_atoms
from ara.grammars.literal_edits import (
    chained,
    claim_edits,
    condition_trades,
    literal_edits,
    operator_drops,
    unchained,
)
from ara.grammars.nesting import (
    AFTER_WINDOW,
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

_SAYS = {AGAIN_AND_AGAIN: "again and again", FOR_GOOD: "from some point on, for good",
         RESTATED: "an operator inside the same one",
         AFTER_WINDOW: "at some point from the window's end on"}
_CLAIMS = {HOLDS: "that anything holds over time (G)",
           HAPPENS: "that anything happens at some point (F)",
           AGAIN_AND_AGAIN: "that anything happens again and again (G(F))"}
_NEVER_USES = ("never uses {}", " or ")


@dataclass(frozen=True)
class Check:
    """One kind of gap.

    Attributes:
        kind: Its name (:data:`KINDS`): the :class:`Gaps` attribute and the ``--json``
            key that hold it.
        find: The gap of an answer to a request: a tuple (empty: none) or a bool.
        mend: Formulas one edit from an answer that close the gap it holds.
        parts: What the warning says of each thing the gap holds, given the request
            (``None``: no sentence to quote).
        clause: The warning's clause for the parts and how they are joined; kinds
            with one clause share it.
        left_out: Whether ``--json`` lists it under ``left_out``.
        timed: Only an interval closes it, so it neither counts nor is mended where a
            grammar has no intervals.
    """

    kind: str
    find: Callable[[Request, Formula], Any]
    mend: Callable[[Request, Formula, Any], list[Formula]]
    parts: Callable[[Any, Request | None], list[str]]
    clause: tuple[str, str]
    left_out: bool = True
    timed: bool = False


def unasked(request: Request, formula: Formula) -> tuple[Formula, ...]:
    """The parts of ``formula`` its request never asks for: nested pairs that restate an
    operator, ``G(F)``, ``F(G)`` or ``G[a,b](F)`` where the sentence has none of the
    words for it, and steps put one after another
    (:func:`~ara.grammars.nesting.sequenced_steps`) where it says "in any order"."""
    pairs = [node for node, kind in nested_pairs(formula)
             if kind == RESTATED or kind not in request.allows]
    ordered = list(sequenced_steps(formula)) if request.any_order else []
    return tuple(pairs + ordered)


def unclaimed(request: Request, formula: Formula) -> tuple[str, ...]:
    """What the request asks to hold, happen or recur that ``formula`` never claims, in
    the order of :attr:`Request.claims`."""
    said = temporal_claims(formula)
    return tuple(claim for claim in request.claims if claim not in said)


def reversed_conditions(request: Request, formula: Formula) -> tuple[Formula, ...]:
    """The implications of ``formula`` that read a condition its sentence names
    (:attr:`Request.conditions`) as a consequence: where no premise names one, those
    whose premise names what the sentence says outside its conditions and whose
    consequence states a condition as the premise should have (:func:`_read_as_result`):
    ``G(at_door -> F(doorbell_rings))`` for "whenever the doorbell rings, go to the door"."""
    arrows = [node for node in walk(formula) if isinstance(node, Implies)]
    if not request.conditions or any(atoms(a.lhs) & request.conditions for a in arrows):
        return ()
    return tuple(a for a in arrows if atoms(a.lhs) & request.outcomes
                 and any(_read_as_result(request, a.rhs, c) for c in request.conditions))


def _read_as_result(request: Request, consequence: Formula, condition: str) -> bool:
    """Whether ``consequence`` states ``condition``, which the sentence affirms, unnegated
    (and not under ``<->``, which has no direction): as a reaction, under an ``F`` or
    ``G``, or in the words the sentence says it in. ``G(drawer_open -> cashier_here)``
    for "never leave the drawer open when no cashier is here" is the contrapositive of
    the right answer, and so is ``G(crusher_running -> guard_on)`` for "never run the
    crusher while its guard is off": a condition the clause negates, or a state it
    names in other words, is no evidence."""
    if condition not in request.affirmed_conditions or {
            negated for name, negated in signed_atoms(consequence) if name == condition} != {False}:
        return False
    return (condition not in atoms_read_now(consequence)
            or condition in request.plain_conditions)


def _written(formula: Formula) -> set[int]:
    ends = set()
    for node in walk(formula):
        if (iv := interval_of(node)) is not None:
            ends |= {iv.lo} | ({iv.hi} if iv.hi is not None else set())
    return ends


def _drops(request: Request, formula: Formula, _held: Any) -> list[Formula]:
    # An operator the sentence never asks for is dropped; where that leaves another
    # (F[0,200](F(G(a))) drops to F[0,200](G(a))), that one is dropped too.
    added = unasked(request, formula)
    drops = operator_drops(formula, added)
    drops += [again for once in drops for again in operator_drops(once, unasked(request, once))]
    return drops + unchained(formula, added)


def _says(text: str) -> str:
    formula = parse(text)
    kinds = [kind for node, kind in nested_pairs(formula) if node == formula]
    return f"{text} ({_SAYS[kinds[0]] if kinds else 'one step after the other'})"


def _asked_by(claim: str, request: Request | None) -> str:
    word = request.asking_word(claim) if request else None
    return _CLAIMS[claim] + (f', which "{word}" asks for' if word else ", as the sentence asks")


#: The checks, in the order gaps are counted, mended and told.
CHECKS = (
    Check("aps", lambda r, f: tuple(ap for ap in r.aps if ap not in atoms(f)),
          lambda r, f, held: literal_edits(f, held),
          lambda held, r: [f"{ap}, a listed proposition," for ap in held],
          _NEVER_USES),
    Check("numbers", lambda r, f: tuple(sorted(r.stated - _written(f))),
          lambda r, f, held: literal_edits(f, (), held),
          lambda held, r: [f"the bound {n} the sentence states" for n in held],
          _NEVER_USES, timed=True),
    Check("unasked", lambda r, f: tuple(dict.fromkeys(map(to_text, unasked(r, f)))),
          _drops, lambda held, r: [_says(text) for text in held],
          ("writes {}, which the sentence never asks for", " and "), left_out=False),
    Check("order", lambda r, f: r.ordered and not orders_in_time(f),
          lambda r, f, held: chained(f), lambda held, r: [""],
          ("orders nothing in time, where the sentence asks for one step after the other",
           "")),
    Check("claims", unclaimed, lambda r, f, held: claim_edits(f, held),
          lambda held, r: [_asked_by(claim, r) for claim in held],
          ("never says {}", " or ")),
    Check("condition", lambda r, f: tuple(dict.fromkeys(map(to_text, reversed_conditions(r, f)))),
          lambda r, f, held: condition_trades(f, reversed_conditions(r, f), r.conditions),
          lambda held, r: list(held),
          ("writes {}, which puts what the sentence names as the condition after the "
           "arrow", " and "), left_out=False),
)
#: The kinds of gap, in :data:`CHECKS`' order.
KINDS = tuple(check.kind for check in CHECKS)


@dataclass(frozen=True)
class Gaps:
    """What an answer leaves out of its request, and what it writes unasked: one
    attribute per entry of :data:`CHECKS`.

    Attributes:
        aps: Listed propositions the answer never uses.
        numbers: Numbers the sentence states that no interval of the answer writes.
        unasked: Subformulas (canonical text) that nest temporal operators or order
            steps as the sentence never asks for (:func:`unasked`).
        order: The sentence asks for steps one after the other and the answer
            orders nothing in time.
        claims: What the sentence asks to hold over time, happen at some point or
            happen again and again, and the answer never claims (:func:`unclaimed`).
        condition: Implications (canonical text) whose consequence holds what the
            sentence names as the condition, where no premise holds one
            (:func:`reversed_conditions`).
    """

    aps: tuple[str, ...] = ()
    numbers: tuple[int, ...] = ()
    unasked: tuple[str, ...] = ()
    order: bool = False
    claims: tuple[str, ...] = ()
    condition: tuple[str, ...] = ()

    def __len__(self) -> int:
        return self.count()

    def count(self, timed: bool = True) -> int:
        """How many gaps it holds; without ``timed``, not the kinds only an interval
        closes."""
        return sum(int(held) if isinstance(held, bool) else len(held)
                   for check, held in self._held() if timed or not check.timed)

    def kinds(self) -> list[str]:
        """The kinds of gap held (:data:`KINDS`), in that order."""
        return [check.kind for check, held in self._held() if held]

    def to_json(self) -> dict:
        """The gaps as ``ara translate --json`` writes them: ``left_out`` (``aps``,
        ``numbers``, ``order``, ``claims``), ``unasked`` and ``condition``."""
        data: dict = {"left_out": {}}
        for check, held in self._held():
            place = data["left_out"] if check.left_out else data
            place[check.kind] = held if isinstance(held, bool) else list(held)
        return data

    @classmethod
    def from_json(cls, data: dict) -> Gaps:
        """The gaps of an answer as :meth:`to_json` wrote them (no gap where ``data``
        has no fields for them: an answer that did not parse, or an older file)."""
        found, left_out = {}, data.get("left_out") or {}
        for check in CHECKS:
            if check.kind in (place := left_out if check.left_out else data):
                held = place[check.kind]
                found[check.kind] = held if isinstance(held, bool) else tuple(held)
        return cls(**found)

    def warning(self, request: Request | None = None) -> str:
        """What to tell a user whose answer has these gaps: such answers were nearly
        always wrong on the held-out sets, so it should not pass silently. Given the
        request, the words that ask for a claim left out are quoted."""
        clauses: dict[tuple[str, str], list[str]] = {}
        for check, held in self._held():
            if held:
                clauses.setdefault(check.clause, []).extend(check.parts(held, request))
        said = [template.format(joiner.join(parts))
                for (template, joiner), parts in clauses.items()]
        return (f"warning: this answer {'; it also '.join(said)}, so it most likely "
                "misreads the sentence. Read it back with `ara stl explain`; rephrasing the "
                "sentence may help.")

    def _held(self) -> list[tuple[Check, Any]]:
        return [(check, getattr(self, check.kind)) for check in CHECKS]


def gaps(request: Request, formula: Formula) -> Gaps:
    """What ``formula``, as an answer to ``request``, leaves out and writes unasked."""
    return Gaps(**{check.kind: check.find(request, formula) for check in CHECKS})


def mends(request: Request, formula: Formula, timed: bool = True) -> list[Formula]:
    """Formulas one edit from ``formula`` that close one of its gaps, kind by kind
    (without ``timed``, not those only an interval closes); they may repeat and break
    the request's grammar."""
    return [mend for check, held in gaps(request, formula)._held()
            if held and (timed or not check.timed)
            for mend in check.mend(request, formula, held)]
