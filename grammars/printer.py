"""The canonical printer: one string per tree, which parses back to the same tree.

Canonical form, by example: ``F(a) & G[0,30](!b)``, ``(a | b) -> X(c)``,
``a U[2,5] (b & c)``, ``!(a & b)``. Rules: a temporal prefix operator always wraps
its argument in parentheses; every binary subformula of another operator is
parenthesized; single spaces surround binary operators and nothing else.
"""

from __future__ import annotations

from ara.grammars.ast import (
    BINARY,
    Always,
    And,
    Atom,
    Const,
    Eventually,
    Formula,
    Iff,
    Implies,
    Interval,
    Next,
    Not,
    Or,
    Until,
)


def to_text(formula: Formula) -> str:
    """Print ``formula`` in canonical form."""
    if isinstance(formula, Atom):
        return formula.name
    if isinstance(formula, Const):
        return "true" if formula.value else "false"
    if isinstance(formula, Not):
        return "!" + _operand(formula.arg)
    if isinstance(formula, Eventually):
        return f"F{interval_text(formula.interval)}({to_text(formula.arg)})"
    if isinstance(formula, Always):
        return f"G{interval_text(formula.interval)}({to_text(formula.arg)})"
    if isinstance(formula, Next):
        return f"X({to_text(formula.arg)})"
    if isinstance(formula, And):
        return " & ".join(_operand(a) for a in formula.args)
    if isinstance(formula, Or):
        return " | ".join(_operand(a) for a in formula.args)
    if isinstance(formula, Implies):
        return f"{_operand(formula.lhs)} -> {_operand(formula.rhs)}"
    if isinstance(formula, Iff):
        return f"{_operand(formula.lhs)} <-> {_operand(formula.rhs)}"
    if isinstance(formula, Until):
        op = f"U{interval_text(formula.interval)}"
        return f"{_operand(formula.lhs)} {op} {_operand(formula.rhs)}"
    raise TypeError(f"not a formula node: {formula!r}")


def interval_text(interval: Interval | None) -> str:
    """``[lo,hi]``, ``[lo,inf]``, or ``""`` for an untimed operator."""
    if interval is None:
        return ""
    hi = "inf" if interval.hi is None else str(interval.hi)
    return f"[{interval.lo},{hi}]"


def _operand(formula: Formula) -> str:
    text = to_text(formula)
    return f"({text})" if isinstance(formula, BINARY) else text
