"""Formulas one edit away from a translation that write what it left out.

A translation that never uses a listed proposition or a stated bound is nearly always
wrong, and often only by one slip: a proposition written in the wrong slot
(``G(empty_bin -> F[0,12](empty_bin))`` for "every time the bin is full, empty it
within 12 steps"), an interval left off an operator (``F(a & F(b))`` for "a, and
within 10 steps after that, b"), a conjunct dropped. :func:`literal_edits` lists every
formula one such edit away that writes a missing literal; a model's score picks among
them (:func:`ara.eval.translate.repair.translate_repaired`).

The edits, for a missing proposition ``q``: an atom becomes ``q``, ``(a | q)`` or
``(a & q)``; a subformula ``s`` becomes ``q -> s``; the whole formula gains a conjunct
``q``, ``F(q)`` or ``G(!q)``. For a missing bound ``n``: a temporal operator gets the
interval ``[0,n]`` (or keeps one end of its interval and takes ``n`` as the other); a
subformula ``s`` becomes ``F[0,n](s)`` or ``G[0,n](s)``; with two missing bounds
``a < b``, an operator gets ``[a,b]``.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from dataclasses import replace
from itertools import combinations

from ara.grammars.ast import (
    Always,
    And,
    Atom,
    Eventually,
    Formula,
    Implies,
    Interval,
    Not,
    Or,
    Until,
    atoms,
    children,
    conjuncts,
    is_temporal,
    map_children,
    walk,
    with_children,
)
from ara.grammars.nesting import AGAIN_AND_AGAIN, HAPPENS, HOLDS
from ara.grammars.printer import to_text

Rebuild = Callable[[Formula], Formula]


def literal_edits(formula: Formula, aps: Sequence[str] = (),
                  bounds: Sequence[int] = ()) -> list[Formula]:
    """Every formula one edit from ``formula`` that writes one of ``aps`` or ``bounds``.

    Args:
        formula: The translation to mend.
        aps: Propositions it should use and does not.
        bounds: Numbers it should write in an interval and does not.

    Returns:
        Distinct formulas (by canonical text), in a fixed order, ``formula`` excluded.
        They may break a request's depth or width limit; check them against its syntax.
    """
    out: dict[str, Formula] = {}
    spots = list(_spots(formula))
    for q in aps:
        new = Atom(q)
        for sub, rebuild in spots:
            if isinstance(sub, Atom):
                _add(out, rebuild(new), rebuild(Or((sub, new))), rebuild(And((sub, new))))
            _add(out, rebuild(Implies(new, sub)))
        _add(out, And((formula, new)), And((formula, Eventually(new))),
             And((formula, Always(Not(new)))))
    for n in bounds:
        for sub, rebuild in spots:
            _add(out, *(rebuild(replace(sub, interval=iv)) for iv in _intervals_with(sub, n)),
                 rebuild(Eventually(sub, Interval(0, n))), rebuild(Always(sub, Interval(0, n))))
    for lo, hi in combinations(sorted(set(bounds)), 2):
        for sub, rebuild in spots:
            if isinstance(sub, (Eventually, Always, Until)):
                _add(out, rebuild(replace(sub, interval=Interval(lo, hi))))
    out.pop(to_text(formula), None)
    return list(out.values())


def _add(out: dict[str, Formula], *formulas: Formula) -> None:
    for f in formulas:
        out.setdefault(to_text(f), f)


def _spots(node: Formula) -> Iterator[tuple[Formula, Rebuild]]:
    """Every subformula of ``node`` (``node`` first, then depth first, left to right),
    with the function that rebuilds ``node`` around a replacement for it."""
    yield node, lambda new: new
    kids = children(node)
    for i, kid in enumerate(kids):
        for sub, rebuild in _spots(kid):
            yield sub, (lambda new, i=i, rebuild=rebuild: with_children(
                node, kids[:i] + (rebuild(new),) + kids[i + 1:]))


def _intervals_with(node: Formula, n: int) -> list[Interval]:
    """Intervals for a temporal operator that write ``n``: ``[0,n]``, and its own
    interval with ``n`` as the new upper or lower end where that stays an interval."""
    if not isinstance(node, (Eventually, Always, Until)):
        return []
    ivs = [Interval(0, n)]
    if (iv := node.interval) is not None:
        if n >= iv.lo:
            ivs.append(Interval(iv.lo, n))
        if iv.hi is not None and n <= iv.hi:
            ivs.append(Interval(n, iv.hi))
    return ivs


def operator_drops(formula: Formula, nodes: Sequence[Formula]) -> list[Formula]:
    """Every formula with one temporal operator of a pair in ``nodes`` dropped: for each
    occurrence of a node ``O1(O2(a))`` in ``formula``, the formula with ``O2(a)`` or
    ``O1(a)`` in its place (a pair the sentence never asks for, such as ``G(F(a))`` for
    "always keep a firm grip on a", :mod:`ara.grammars.nesting`).

    Returns:
        Distinct formulas (by canonical text), in a fixed order, ``formula`` excluded.
    """
    out: dict[str, Formula] = {}
    targets = set(nodes)
    for sub, rebuild in _spots(formula):
        if sub in targets and isinstance(sub, (Eventually, Always)):
            inner = sub.arg
            if isinstance(inner, (Eventually, Always)):
                _add(out, rebuild(inner), rebuild(replace(sub, arg=inner.arg)))
    out.pop(to_text(formula), None)
    return list(out.values())


def unchained(formula: Formula, nodes: Sequence[Formula]) -> list[Formula]:
    """Every formula with one ordered step of ``nodes`` set free: ``F(a & F(b))``
    becomes ``F(a) & F(b)`` (steps asked for "in any order")."""
    out: dict[str, Formula] = {}
    targets = set(nodes)
    for sub, rebuild in _spots(formula):
        if sub in targets and isinstance(sub, Eventually) and isinstance(sub.arg, And):
            steps = [a for a in sub.arg.args if isinstance(a, Eventually)]
            rest = [a for a in sub.arg.args if not isinstance(a, Eventually)]
            if steps:
                first = (replace(sub, arg=rest[0] if len(rest) == 1 else And(tuple(rest)))
                         if rest else None)
                parts = ([first] if first is not None else []) + steps
                _add(out, rebuild(parts[0] if len(parts) == 1 else And(tuple(parts))))
    out.pop(to_text(formula), None)
    return list(out.values())


def condition_trades(formula: Formula, nodes: Sequence[Formula],
                     conditions: frozenset[str]) -> list[Formula]:
    """Every formula with a premise's proposition and one of ``conditions`` in the
    consequence of an implication of ``nodes`` trading places, each taking the other's
    sign: ``G(at_door -> F(bell))`` becomes ``G(bell -> F(at_door))`` (a condition read as
    the consequence), ``G(!running -> guard_off)`` becomes ``G(guard_off -> !running)``.
    Renaming alone would give ``G(!guard_off -> running)``, the contrapositive of the
    answer, which says the same.

    Returns:
        Distinct formulas (by canonical text), in a fixed order, ``formula`` excluded.
    """
    out: dict[str, Formula] = {}
    targets = set(nodes)
    for sub, rebuild in _spots(formula):
        if sub not in targets or not isinstance(sub, Implies):
            continue
        for premise in sorted(atoms(sub.lhs) - conditions):
            for condition in sorted(atoms(sub.rhs) & conditions):
                _add(out, rebuild(_trade(sub, premise, condition)))
    out.pop(to_text(formula), None)
    return list(out.values())


def _trade(node: Implies, premise: str, condition: str) -> Formula:
    """``node`` with ``premise`` and ``condition`` put for each other everywhere in it,
    negated where their first literals differ in sign (so ``!premise`` in the premise
    becomes ``condition``), double negations dropped."""
    flip = isinstance(_literal(node.lhs, premise), Not) != isinstance(
        _literal(node.rhs, condition), Not)

    def put(n: Formula) -> Formula:
        if isinstance(n, Atom) and n.name in (premise, condition):
            other = Atom(condition if n.name == premise else premise)
            return Not(other) if flip else other
        kid = map_children(n, put)
        return kid.arg.arg if isinstance(kid, Not) and isinstance(kid.arg, Not) else kid

    return put(node)


def _literal(node: Formula, name: str) -> Formula:
    """How ``name`` first occurs in ``node``: negated (``!name``) or not."""
    for sub in walk(node):
        if isinstance(sub, Not) and sub.arg == Atom(name):
            return sub
        if sub == Atom(name):
            return sub
    raise ValueError(f"{name} does not occur in {to_text(node)}")


def chained(formula: Formula) -> list[Formula]:
    """Every formula with the ``F`` conjuncts of one conjunction ordered as written:
    ``F(a) & F(b) & F(c)`` becomes ``F(a & F(b & F(c)))``, each step keeping its
    interval (steps asked for "one after the other")."""
    out: dict[str, Formula] = {}
    for sub, rebuild in _spots(formula):
        if not isinstance(sub, And):
            continue
        operands = conjuncts(sub)
        steps = [c for c in operands if isinstance(c, Eventually)]
        if len(steps) < 2:
            continue
        chain = steps[-1]
        for step in reversed(steps[:-1]):
            chain = replace(step, arg=And((step.arg, chain)))
        others = [c for c in operands if not isinstance(c, Eventually)]
        _add(out, rebuild(And((*others, chain)) if others else chain))
    out.pop(to_text(formula), None)
    return list(out.values())


def claim_edits(formula: Formula, claims: Sequence[str]) -> list[Formula]:
    """Every formula one edit from ``formula`` that makes one of ``claims``
    (:func:`~ara.grammars.nesting.temporal_claims`) the sentence asks for and it lacks:

    - :data:`~ara.grammars.nesting.HOLDS` ("keep the door locked between step 10 and
      20", "go there and stay there"): an ``F`` becomes a ``G`` with its interval, or
      ``F(G(s))``; a part with no temporal operator ``s`` becomes ``G(s)``, a conjunction
      of two such ``a & b`` becomes ``a U b`` or ``b U a``;
    - :data:`~ara.grammars.nesting.HAPPENS` ("never during the first 20 seconds, but at
      some point"): a ``G`` becomes an ``F``, ``s`` becomes ``F(s)``, the formula gains a
      conjunct ``F(a)`` for one of its propositions;
    - :data:`~ara.grammars.nesting.AGAIN_AND_AGAIN` ("every so often", "at least once in
      every 10-step window"): ``G(s)`` becomes ``G(F(s))`` (``G[0,10](s)`` also
      ``G(F[0,10](s))``), ``F(s)`` becomes ``G(F(s))``, and ``s`` becomes ``G(F(s))``.

    Returns:
        Distinct formulas (by canonical text), in a fixed order, ``formula`` excluded.
    """
    out: dict[str, Formula] = {}
    parts = {id(node) for node in _plain_parts(formula)}
    for sub, rebuild in _spots(formula):
        plain = id(sub) in parts
        for claim in claims:
            if claim == HOLDS:
                if isinstance(sub, Eventually):
                    _add(out, rebuild(Always(sub.arg, sub.interval)))
                    if not is_temporal(sub.arg):
                        _add(out, rebuild(replace(sub, arg=Always(sub.arg))))
                if plain:
                    _add(out, rebuild(Always(sub)))
                if plain and isinstance(sub, And) and len(sub.args) == 2:
                    a, b = sub.args
                    _add(out, rebuild(Until(a, b)), rebuild(Until(b, a)))
            elif claim == HAPPENS:
                if isinstance(sub, Always):
                    _add(out, rebuild(Eventually(sub.arg, sub.interval)))
                if plain:
                    _add(out, rebuild(Eventually(sub)))
            elif claim == AGAIN_AND_AGAIN:
                if isinstance(sub, Always) and not isinstance(sub.arg, Eventually):
                    _add(out, rebuild(replace(sub, arg=Eventually(sub.arg))))
                    if sub.interval is not None:
                        _add(out, rebuild(Always(Eventually(sub.arg, sub.interval))))
                if isinstance(sub, Eventually):
                    _add(out, rebuild(Always(sub)))
                if plain:
                    _add(out, rebuild(Always(Eventually(sub))))
    if HAPPENS in claims:
        for ap in sorted(atoms(formula)):
            _add(out, And((formula, Eventually(Atom(ap)))))
    out.pop(to_text(formula), None)
    return list(out.values())


def _plain_parts(node: Formula, under_operator: bool = False) -> Iterator[Formula]:
    """The largest parts of ``node`` with no temporal operator, bar those an ``F`` or
    ``G`` already applies to (their edits are the operator's own)."""
    if not is_temporal(node):
        if not under_operator:
            yield node
        return
    for kid in children(node):
        yield from _plain_parts(kid, isinstance(node, (Eventually, Always)))
