"""Temporal operators inside one another: what each such pair says, and which
formulas order steps in time.

``F`` and ``G`` nested one in the other say something that needs words of its own:
``G(F(a))`` "a again and again", ``F(G(a))`` "a from some point on, for good",
``G[0,45](F(a))`` "at every step of the first 45, a at some point later", which is no
more than ``F[45,inf](a)`` and is what a slip gives for "keep a on for 45 minutes". The same
operator nested in itself, with one of the two unbounded, says no more than one of
them would (``F(F(a))`` is ``F(a)``, ``G(G(a))`` is ``G(a)``) or makes a bound void
(``F[10,25](F(a))`` is ``F[10,inf](a)``, ``G(G[0,5](a))`` is ``G(a)``): a sentence
asks for such a formula only by accident, so a translation that writes one has most
likely slipped (docs/model-card.md, "How repair and the confidence note work").

An ``F`` inside the conjunction of another (``F(a & F(b))``) orders two steps; "in
any order" asks for none, and "one after the other" for one.

What a formula says over time, whatever operators it uses to say it
(:func:`temporal_claims`): that something holds over a stretch of time
(:data:`HOLDS`: ``G``, or a negated ``F``: ``!F(a)`` is ``G(!a)``), that something happens
at some point (:data:`HAPPENS`), that it happens again and again (:data:`AGAIN_AND_AGAIN`:
a claim to happen inside a claim to hold). A sentence that says "always", "at some
point" or "repeatedly" asks for one of these.
"""

from __future__ import annotations

from collections.abc import Iterator

from ara.grammars.ast import (
    Always,
    And,
    Eventually,
    Formula,
    Iff,
    Implies,
    Not,
    Until,
    children,
    is_temporal,
    walk,
)

#: The nested pairs :func:`nested_pairs` names: an operator over another, unbounded.
AGAIN_AND_AGAIN = "G(F)"
FOR_GOOD = "F(G)"
AFTER_WINDOW = "G[a,b](F)"
RESTATED = "restated"
#: What :func:`temporal_claims` names besides :data:`AGAIN_AND_AGAIN`.
HOLDS = "G"
HAPPENS = "F"


def nested_pairs(formula: Formula) -> Iterator[tuple[Formula, str]]:
    """Every ``F`` or ``G`` node of ``formula`` whose argument is an ``F`` or ``G``,
    with what the pair says, where it says something of note:

    - :data:`RESTATED`: the same operator twice, one of them unbounded;
    - :data:`AGAIN_AND_AGAIN`: an unbounded ``G`` over an unbounded ``F``;
    - :data:`FOR_GOOD`: an ``F`` (bounded or not) over an unbounded ``G``;
    - :data:`AFTER_WINDOW`: a ``G`` bounded at both ends over an unbounded ``F``.

    Other pairs (``G(F[0,10](a))`` "at least once in every 10 steps", ``F(G[0,5](a))``
    "at some point, a for 5 steps", both bounded) are left out: each says what its
    words say.
    """
    for node in walk(formula):
        if not isinstance(node, (Eventually, Always)):
            continue
        inner = node.arg
        if not isinstance(inner, (Eventually, Always)):
            continue
        if type(inner) is type(node):
            if node.interval is None or inner.interval is None:
                yield node, RESTATED
        elif inner.interval is None and (isinstance(node, Eventually) or node.interval is None):
            yield node, FOR_GOOD if isinstance(node, Eventually) else AGAIN_AND_AGAIN
        elif inner.interval is None and node.interval.hi is not None:
            yield node, AFTER_WINDOW


def sequenced_steps(formula: Formula) -> Iterator[Formula]:
    """Every ``F`` node of ``formula`` whose argument is a conjunction with an ``F`` in
    it: ``F(a & F(b))``, "a, and after that b", an order between two steps."""
    for node in walk(formula):
        if (isinstance(node, Eventually) and isinstance(node.arg, And)
                and any(isinstance(arg, Eventually) for arg in node.arg.args)):
            yield node


def orders_in_time(formula: Formula) -> bool:
    """Whether ``formula`` puts anything after anything else: an until, a temporal
    operator inside an ``F`` or ``G``, or an implication whose consequence is temporal
    (``G(a -> F(b))``, "b after each a")."""
    for node in walk(formula):
        if isinstance(node, Until):
            return True
        if isinstance(node, (Eventually, Always)) and is_temporal(node.arg):
            return True
        if isinstance(node, Implies) and is_temporal(node.rhs):
            return True
    return False


def temporal_claims(formula: Formula) -> frozenset[str]:
    """What ``formula`` claims over time: :data:`HOLDS` for a ``G``, :data:`HAPPENS` for
    an ``F``, :data:`AGAIN_AND_AGAIN` for an ``F`` inside a ``G``, each read as written
    and through negations too (``!F(a)`` also holds, ``G(a -> F(b))`` also recurs, an
    until both holds and happens): the words of a sentence name the operators its
    formula writes ("if at some point a, b" is ``F(a) -> b``) as often as what they
    mean."""
    return frozenset(_claims(formula, positive=True) | _claims(formula, positive=None))


def _claims(node: Formula, positive: bool | None) -> set[str]:
    """Claims read through negations (``positive``: the polarity of ``node``), or as
    written where ``positive`` is None."""
    flip = None if positive is None else not positive
    if isinstance(node, Not):
        return _claims(node.arg, flip)
    if isinstance(node, Implies):
        return _claims(node.lhs, flip) | _claims(node.rhs, positive)
    if isinstance(node, Iff) and positive is not None:
        return set().union(*(_claims(side, sign) for side in (node.lhs, node.rhs)
                             for sign in (True, False)))
    if isinstance(node, Until):
        return {HOLDS, HAPPENS} | _claims(node.lhs, positive) | _claims(node.rhs, positive)
    if isinstance(node, (Eventually, Always)):
        inner = _claims(node.arg, positive)
        holds = isinstance(node, Always) == (positive is not False)
        if holds and HAPPENS in inner:
            inner.add(AGAIN_AND_AGAIN)
        return inner | {HOLDS if holds else HAPPENS}
    return set().union(*(_claims(kid, positive) for kid in children(node)))
