"""The STL abstract syntax tree: immutable, hashable, checked on construction.

Time is discrete (one step per sample). A temporal operator carries an optional
:class:`Interval`; ``None`` means the untimed LTL operator. ``Interval(0, None)`` is
kept distinct from ``None`` although both mean the same thing, so that printing and
parsing round-trip exactly.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace

from ara.errors import AraError

#: Words the surface syntax reserves; no atomic proposition may be named so.
KEYWORDS = frozenset({"F", "G", "X", "U", "true", "false", "inf"})


class ASTError(AraError, ValueError):
    """A node built with arguments that make no formula."""


@dataclass(frozen=True, slots=True)
class Interval:
    """A closed interval of time steps ``[lo, hi]``; ``hi=None`` is unbounded.

    Args:
        lo: First step, ``>= 0``.
        hi: Last step, ``>= lo``, or ``None`` for no upper bound.
    """

    lo: int
    hi: int | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.lo, int) or self.lo < 0:
            raise ASTError(f"interval lower bound must be an integer >= 0, got {self.lo!r}")
        if self.hi is not None and (not isinstance(self.hi, int) or self.hi < self.lo):
            raise ASTError(
                f"interval upper bound must be an integer >= lower bound {self.lo}, "
                f"got {self.hi!r}; write None for an unbounded interval"
            )

    @property
    def bound(self) -> int:
        """The largest finite number the interval mentions."""
        return self.lo if self.hi is None else self.hi


@dataclass(frozen=True, slots=True)
class Atom:
    """An atomic proposition, e.g. ``prop_1`` or ``at_cell_3_4``."""

    name: str

    def __post_init__(self) -> None:
        if not is_identifier(self.name):
            raise ASTError(
                f"atomic proposition names are [A-Za-z_][A-Za-z0-9_]*, got {self.name!r}"
            )
        if self.name in KEYWORDS:
            raise ASTError(
                f"{self.name!r} is a reserved word and cannot name an atomic proposition; "
                f"reserved: {', '.join(sorted(KEYWORDS))}"
            )


@dataclass(frozen=True, slots=True)
class Const:
    """``true`` or ``false``."""

    value: bool


@dataclass(frozen=True, slots=True)
class Not:
    """Negation ``!arg``."""

    arg: Formula


@dataclass(frozen=True, slots=True)
class And:
    """Conjunction of two or more formulas, in order."""

    args: tuple[Formula, ...]

    def __post_init__(self) -> None:
        _check_nary("And", self.args)


@dataclass(frozen=True, slots=True)
class Or:
    """Disjunction of two or more formulas, in order."""

    args: tuple[Formula, ...]

    def __post_init__(self) -> None:
        _check_nary("Or", self.args)


@dataclass(frozen=True, slots=True)
class Implies:
    """Implication ``lhs -> rhs``."""

    lhs: Formula
    rhs: Formula


@dataclass(frozen=True, slots=True)
class Iff:
    """Equivalence ``lhs <-> rhs``."""

    lhs: Formula
    rhs: Formula


@dataclass(frozen=True, slots=True)
class Eventually:
    """``F arg`` / ``F[a,b] arg``: arg holds at some step in the interval."""

    arg: Formula
    interval: Interval | None = None


@dataclass(frozen=True, slots=True)
class Always:
    """``G arg`` / ``G[a,b] arg``: arg holds at every step in the interval."""

    arg: Formula
    interval: Interval | None = None


@dataclass(frozen=True, slots=True)
class Next:
    """``X arg``: arg holds at the next step."""

    arg: Formula


@dataclass(frozen=True, slots=True)
class Until:
    """``lhs U rhs`` / ``lhs U[a,b] rhs`` (strong until).

    rhs holds at some step t in the interval and lhs holds at every step before t.
    """

    lhs: Formula
    rhs: Formula
    interval: Interval | None = None


Formula = Atom | Const | Not | And | Or | Implies | Iff | Eventually | Always | Next | Until
BINARY = (And, Or, Implies, Iff, Until)
#: The temporal operators: a formula without any speaks of one instant.
TEMPORAL = (Eventually, Always, Next, Until)


def _check_nary(kind: str, args: object) -> None:
    if not isinstance(args, tuple) or len(args) < 2:
        raise ASTError(f"{kind} needs a tuple of at least 2 formulas, got {args!r}")


def is_identifier(name: str) -> bool:
    """Whether ``name`` is lexically an identifier of the surface syntax."""
    return (
        bool(name)
        and (name[0].isascii() and (name[0].isalpha() or name[0] == "_"))
        and all(c.isascii() and (c.isalnum() or c == "_") for c in name)
    )


def children(node: Formula) -> tuple[Formula, ...]:
    """The direct subformulas of ``node``, left to right."""
    if isinstance(node, (Atom, Const)):
        return ()
    if isinstance(node, (And, Or)):
        return node.args
    if isinstance(node, (Implies, Iff, Until)):
        return (node.lhs, node.rhs)
    return (node.arg,)


def walk(node: Formula) -> Iterator[Formula]:
    """Every node of the tree, parents before children."""
    yield node
    for child in children(node):
        yield from walk(child)


def atoms(node: Formula) -> frozenset[str]:
    """The names of the atomic propositions that occur in ``node``."""
    return frozenset(n.name for n in walk(node) if isinstance(n, Atom))


def conjuncts(node: Formula) -> list[Formula]:
    """The operands of ``node`` as one conjunction, in order, whatever its bracketing
    (``[a, b, c]`` for ``(a & b) & c``); ``[node]`` if it is no conjunction."""
    if isinstance(node, And):
        return [c for arg in node.args for c in conjuncts(arg)]
    return [node]


def atoms_read_now(node: Formula) -> frozenset[str]:
    """The propositions ``node`` reads at its first instant only: those outside every
    temporal operator (``a`` in ``a -> F(b)``, none in ``G(a)``)."""
    if isinstance(node, Atom):
        return frozenset({node.name})
    if isinstance(node, TEMPORAL):
        return frozenset()
    return frozenset().union(*(atoms_read_now(c) for c in children(node)))


def is_temporal(formula: Formula) -> bool:
    """Whether ``formula`` has a temporal operator anywhere."""
    return any(isinstance(node, TEMPORAL) for node in walk(formula))


def signed_atoms(node: Formula, negated: bool = False) -> frozenset[tuple[str, bool]]:
    """The propositions of ``node``, each with whether it occurs negated: under an odd
    number of negations, an implication's premise counting as one (``a -> !b`` gives
    ``(a, True)`` and ``(b, True)``); under ``<->``, with both signs."""
    if isinstance(node, Atom):
        return frozenset({(node.name, negated)})
    if isinstance(node, Not):
        return signed_atoms(node.arg, not negated)
    if isinstance(node, Implies):
        return signed_atoms(node.lhs, not negated) | signed_atoms(node.rhs, negated)
    if isinstance(node, Iff):
        return frozenset().union(*(signed_atoms(c, n) for c in children(node)
                                   for n in (negated, not negated)))
    return frozenset().union(*(signed_atoms(c, negated) for c in children(node)))


def interval_of(node: Formula) -> Interval | None:
    """The node's interval, or ``None`` for untimed and non-temporal nodes."""
    return getattr(node, "interval", None)


def max_bound(node: Formula) -> int:
    """The largest number written in any interval of ``node`` (0 if none)."""
    return max((iv.bound for n in walk(node) if (iv := interval_of(n)) is not None), default=0)


def depth(node: Formula) -> int:
    """Operator nesting depth: 0 for an atom or constant."""
    kids = children(node)
    return 0 if not kids else 1 + max(depth(k) for k in kids)


def with_children(node: Formula, kids: tuple[Formula, ...]) -> Formula:
    """A copy of ``node`` whose direct subformulas are ``kids`` (as :func:`children`
    lists them), its operator and interval kept."""
    if isinstance(node, (Atom, Const)):
        return node
    if isinstance(node, (And, Or)):
        return type(node)(kids)
    if isinstance(node, (Implies, Iff, Until)):
        return replace(node, lhs=kids[0], rhs=kids[1])
    return replace(node, arg=kids[0])


def map_children(node: Formula, fn: Callable[[Formula], Formula]) -> Formula:
    """A copy of ``node`` with ``fn`` applied to each direct subformula."""
    return with_children(node, tuple(fn(child) for child in children(node)))


def rename_atoms(node: Formula, names: dict[str, str]) -> Formula:
    """Rename atomic propositions; names absent from ``names`` stay as they are."""
    if isinstance(node, Atom):
        return Atom(names.get(node.name, node.name))
    return map_children(node, lambda child: rename_atoms(child, names))
