"""STL over action propositions -> an event program: which events, in what order, when.

The paper's remark (App. A: "extracting spatial propositions and decoupling temporal
constraints") taken seriously. A robot's propositions are of three kinds
(:class:`Vocabulary`):

- *events*: an action at a cell, true at the one step the robot does it
  (``pick_j3`` at (1, 4)); a plan does each required event once;
- *regions*: sets of cells, whose only use is ``G !region`` (keep out: distances
  are computed without those cells);
- *invariants*: propositions that hold at every step (``actuation``).

The compiler walks the formula's AST (from :mod:`ara.grammars`, never text) and
emits, relative to an *anchor* (the start, or an earlier event):

================================  ===============================================
``F[a,b] x``, ``F[a,b](x & rest)``  event x with a <= t_x - t_anchor <= b; rest
                                  anchored at x
``(!y & ...) U[a,b] x``           as ``F[a,b] x``, and no y between anchor and x
``G(x -> psi)``                   psi anchored at x, if x happens
``G !region``, ``G invariant``    keep out of the region; nothing
``x`` (an event)                  x at the anchor's step
================================  ===============================================

Conjunctions combine. Anything else (disjunction, negated events, bounded G over
events, ...) raises :class:`UnsupportedSpec` naming the subformula, which helpers
report as "cannot help" instead of planning something the formula does not say.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from ara.coordination.world import Cell
from ara.errors import AraError
from ara.grammars import Always, And, Atom, Const, Eventually, Formula, Implies, Not, Or, Until
from ara.grammars import to_text as stl_text
from ara.grammars.ast import conjuncts as and_operands

START = "start"


class UnsupportedSpec(AraError, ValueError):
    """A formula outside the event fragment, or over propositions the robot lacks."""


@dataclass(frozen=True)
class Vocabulary:
    """What a robot's propositions mean.

    Args:
        events: Event proposition -> the cell where it happens.
        regions: Region proposition -> its cells.
        invariants: Propositions true at every step.
        dwell: Steps an event keeps the robot at its cell (the paper's tau_c).
    """

    events: Mapping[str, Cell]
    regions: Mapping[str, frozenset[Cell]] = field(default_factory=dict)
    invariants: frozenset[str] = frozenset()
    dwell: Mapping[str, int] = field(default_factory=dict)

    def __post_init__(self) -> None:
        kinds = [set(self.events), set(self.regions), set(self.invariants)]
        for i in range(3):
            for j in range(i + 1, 3):
                if kinds[i] & kinds[j]:
                    raise UnsupportedSpec(f"propositions of two kinds: {kinds[i] & kinds[j]}")
        if START in self.events:
            raise UnsupportedSpec(f"{START!r} is reserved for the plan's first step")

    def merged(self, other: Vocabulary) -> Vocabulary:
        """Both vocabularies; a proposition in both must mean the same."""
        for name, cell in other.events.items():
            if self.events.get(name, cell) != cell:
                raise UnsupportedSpec(f"{name} names two cells: {self.events[name]} and {cell}")
        return Vocabulary({**self.events, **other.events}, {**self.regions, **other.regions},
                          self.invariants | other.invariants, {**self.dwell, **other.dwell})


@dataclass(frozen=True)
class Window:
    """``lo <= t_event - t_anchor <= hi`` (``hi=None``: no bound); event after anchor."""

    anchor: str
    event: str
    lo: int = 0
    hi: int | None = None


@dataclass(frozen=True)
class NotBetween:
    """No ``event`` strictly after ``anchor`` and before ``until`` in the plan's order."""

    event: str
    anchor: str
    until: str


@dataclass
class EventProgram:
    """The constraints a formula puts on one robot's sequence of events."""

    events: list[str] = field(default_factory=list)
    windows: list[Window] = field(default_factory=list)
    exclusions: list[NotBetween] = field(default_factory=list)
    avoid: set[Cell] = field(default_factory=set)
    groups: dict[str, set[str]] = field(default_factory=dict)

    def require(self, event: str) -> bool:
        if event in self.events:
            return False
        self.events.append(event)
        return True


def compile_spec(conjuncts: Mapping[str, Formula], vocab: Vocabulary) -> EventProgram:
    """Compile named conjuncts (e.g. ``{"own": ..., "help": ...}``) into one program.

    The names become :attr:`EventProgram.groups` (the events each conjunct requires),
    so an objective can weigh one part, such as the time until the help job is done.

    Raises:
        UnsupportedSpec: Naming the subformula that is outside the fragment.
    """
    program = EventProgram()
    pending: list[tuple[str, str, Formula]] = []  # (group, trigger, consequent)
    for group, formula in conjuncts.items():
        before = set(program.events)
        _compile(formula, START, program, vocab, pending, group)
        program.groups.setdefault(group, set()).update(set(program.events) - before)
    # G(x -> psi) binds once x is required, and psi may require the trigger of another.
    changed = True
    while changed:
        changed = False
        for item in list(pending):
            group, trigger, consequent = item
            if trigger in program.events:
                pending.remove(item)
                before = set(program.events)
                _compile(consequent, trigger, program, vocab, pending, group)
                program.groups[group].update(set(program.events) - before)
                changed = True
    return program


def _compile(f: Formula, anchor: str, program: EventProgram, vocab: Vocabulary,
             pending: list, group: str) -> None:
    if isinstance(f, And):
        for arg in f.args:
            _compile(arg, anchor, program, vocab, pending, group)
    elif isinstance(f, Const) and f.value:
        return
    elif isinstance(f, Atom):
        if f.name in vocab.invariants:
            return
        _visit(f, anchor, 0, 0, program, vocab, pending, group)
    elif isinstance(f, Eventually):
        lo, hi = (f.interval.lo, f.interval.hi) if f.interval else (0, None)
        _visit(f.arg, anchor, lo, hi, program, vocab, pending, group)
    elif isinstance(f, Until):
        lo, hi = (f.interval.lo, f.interval.hi) if f.interval else (0, None)
        head = _visit(f.rhs, anchor, lo, hi, program, vocab, pending, group)
        for blocked in _negated_events(f.lhs, vocab, f):
            program.exclusions.append(NotBetween(blocked, anchor, head))
    elif isinstance(f, Always) and f.interval is None:
        _always(f, anchor, program, vocab, pending, group)
    else:
        raise UnsupportedSpec(f"cannot plan for {stl_text(f)!r}: the planner handles "
                              "conjunctions of F, U and G(x -> ...) over events, and G !region")


def _visit(f: Formula, anchor: str, lo: int, hi: int | None, program: EventProgram,
           vocab: Vocabulary, pending: list, group: str) -> str:
    """``f`` holds lo..hi steps after the anchor: its head event, then the rest."""
    parts = and_operands(f)  # the grammar writes two per &: (a & b) & c is a & b & c
    heads = [p for p in parts if isinstance(p, Atom) and p.name in vocab.events]
    if not heads:
        raise UnsupportedSpec(f"{stl_text(f)!r} names no event the robot can do "
                              f"(events: {', '.join(sorted(vocab.events)) or 'none'})")
    head = heads[0].name
    if head == anchor:
        raise UnsupportedSpec(f"{head} must happen after itself")
    program.require(head)
    program.windows.append(Window(anchor, head, lo, hi))
    for p in parts:
        if p is heads[0]:
            continue
        if isinstance(p, Atom) and p.name in vocab.events:
            program.require(p.name)
            program.windows.append(Window(head, p.name, 0, 0))
        else:
            _compile(p, head, program, vocab, pending, group)
    return head


def _always(f: Always, anchor: str, program: EventProgram, vocab: Vocabulary,
            pending: list, group: str) -> None:
    body = f.arg
    if isinstance(body, Implies) and isinstance(body.lhs, Atom) and body.lhs.name in vocab.events:
        pending.append((group, body.lhs.name, body.rhs))
        return
    for p in and_operands(body):
        if isinstance(p, Atom) and p.name in vocab.invariants:
            continue
        if isinstance(p, Not) and isinstance(p.arg, Atom) and p.arg.name in vocab.regions:
            program.avoid |= set(vocab.regions[p.arg.name])
            continue
        raise UnsupportedSpec(f"cannot plan for G({stl_text(p)}): under G the planner "
                              "handles x -> ..., !region and invariants")


def _negated_events(f: Formula, vocab: Vocabulary, whole: Formula) -> list[str]:
    """The events of ``!a``, ``!a & !b``, ``!(a | b)``; regions and invariants: none."""
    if isinstance(f, Const) and f.value:
        return []
    if isinstance(f, And):
        return [e for arg in f.args for e in _negated_events(arg, vocab, whole)]
    if isinstance(f, Not) and isinstance(f.arg, Or):
        return [e for arg in f.arg.args for e in _negated_events(Not(arg), vocab, whole)]
    if isinstance(f, Not) and isinstance(f.arg, Atom):
        if f.arg.name in vocab.events:
            return [f.arg.name]
    if isinstance(f, Atom) and f.name in vocab.invariants:
        return []
    raise UnsupportedSpec(f"cannot plan for {stl_text(whole)!r}: the left side of U must "
                          "negate events")
