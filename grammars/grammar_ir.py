"""A small context-free grammar IR with two emitters: GBNF (llama.cpp) and Lark.

Both emitted texts come from the same :class:`Grammar` value, so they cannot drift
apart. The IR has no left recursion by construction of its users, since llama.cpp
rejects it. It also knows its own shortest and longest derivations. The longest
one makes a depth- and arity-bounded grammar's termination guarantee concrete: no
string of the language is longer than ``max_length()`` characters.
"""

from __future__ import annotations

import functools
import hashlib
import math
import random
from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class Lit:
    """A literal string."""

    text: str


@dataclass(frozen=True, slots=True)
class Chars:
    """One character from a class, given as ``(first, last)`` ranges, e.g. ``(("0", "9"),)``."""

    ranges: tuple[tuple[str, str], ...]

    def members(self) -> list[str]:
        return [chr(c) for lo, hi in self.ranges for c in range(ord(lo), ord(hi) + 1)]


@dataclass(frozen=True, slots=True)
class Ref:
    """A reference to another rule by name."""

    name: str


@dataclass(frozen=True, slots=True)
class Opt:
    """Zero or one of a sequence."""

    items: tuple[Item, ...]


@dataclass(frozen=True, slots=True)
class Star:
    """Zero or more of a sequence."""

    items: tuple[Item, ...]


Item = Lit | Chars | Ref | Opt | Star
Seq = tuple[Item, ...]


@dataclass(frozen=True, slots=True)
class Rule:
    """``name ::= alt_1 | alt_2 | ...``; each alternative is a sequence of items."""

    name: str
    alts: tuple[Seq, ...]


def _memoized(method):
    """Cache a no-argument method's result on the (immutable) grammar instance."""
    name = method.__name__

    @functools.wraps(method)
    def wrapper(self):
        memo = self.__dict__.setdefault("_memo", {})
        if name not in memo:
            memo[name] = method(self)
        return memo[name]

    return wrapper


@dataclass(frozen=True)
class Grammar:
    """A grammar: its rules and the name of the start rule.

    Rule names use ``[a-z0-9_]``; the emitters map them to each format's rules.
    """

    rules: tuple[Rule, ...]
    root: str

    def __post_init__(self) -> None:
        names = [r.name for r in self.rules]
        if len(set(names)) != len(names):
            raise ValueError(f"duplicate rule names in {names}")
        known = set(names)
        missing = {ref for r in self.rules for ref in _refs_in_alts(r.alts)} - known
        if self.root not in known or missing:
            raise ValueError(f"undefined rules: {sorted(missing | ({self.root} - known))}")

    @property
    def by_name(self) -> dict[str, Rule]:
        return {r.name: r for r in self.rules}

    def with_prefix(self, text: str) -> Grammar:
        """The language ``text + w`` for each string ``w`` of this one.

        Decoders use it for the space a model writes after ``"STL:"``, so that the
        answer tokenizes as in training; the caller strips the prefix again.
        """
        return self._wrapped("prefixed", (Lit(text), Ref(self.root)))

    def with_suffix(self, text: str) -> Grammar:
        """The language ``w + text`` for each string ``w`` of this one.

        Decoders end an answer with the newline a model writes after it in training.
        A grammar that refused that end marker would leave the model to pick among the
        operators that may continue a complete formula (``a -> ...``) and the end of
        text, which it was never taught to emit there; the caller strips the suffix.
        """
        return self._wrapped("suffixed", (Ref(self.root), Lit(text)))

    def _wrapped(self, tag: str, items: tuple) -> Grammar:
        """This grammar under a new start rule ``items``, named after the old root."""
        name = f"{self.root}_{tag}"
        while name in self.by_name:
            name += "_"
        return Grammar((Rule(name, (items,)), *self.rules), root=name)

    @_memoized
    def to_gbnf(self) -> str:
        """The grammar in llama.cpp's GBNF; the start rule is named ``root``."""
        return self._emit("root", _gbnf_name, " ::= ", _gbnf_chars)

    @_memoized
    def to_lark(self) -> str:
        """The grammar in Lark syntax (outlines, llguidance); the start rule is ``start``."""
        return self._emit("start", lambda rule: "r_" + rule, ": ", _lark_chars)

    def _emit(self, root: str, rename, define: str, chars) -> str:
        """One rule a line, ``name<define>alt | alt``; the two formats differ only in
        rule names, the definition sign and how a character class is written."""
        name = {r.name: (root if r.name == self.root else rename(r.name)) for r in self.rules}
        return "".join(
            name[rule.name] + define
            + " | ".join(_seq_text(seq, name, _quote, chars) for seq in rule.alts) + "\n"
            for rule in self.rules)

    @_memoized
    def sha256(self) -> str:
        """Content hash of the grammar (of its GBNF text)."""
        return hashlib.sha256(self.to_gbnf().encode()).hexdigest()

    @_memoized
    def min_lengths(self) -> dict[str, int]:
        """Length in characters of each rule's shortest derivation."""
        return _min_lengths(self)

    @_memoized
    def max_length(self) -> float:
        """Length of the longest string in the language (``math.inf`` when unbounded)."""
        return _max_length(self)

    def sample(self, rng: random.Random, budget: int = 40) -> str:
        """Draw a random string of the language.

        Each rule expansion spends one unit of ``budget``; once it is spent, every
        choice takes the shortest way out, so sampling always terminates.
        """
        shortest = self.min_lengths()
        rules = self.by_name
        state = {"left": budget}
        out: list[str] = []

        def seq_len(seq: Seq) -> float:
            return sum(_item_min(i, shortest) for i in seq)

        def expand_seq(seq: Seq) -> None:
            for item in seq:
                expand(item)

        def expand(item: Item) -> None:
            if isinstance(item, Lit):
                out.append(item.text)
            elif isinstance(item, Chars):
                out.append(rng.choice(item.members()))
            elif isinstance(item, Opt):
                if state["left"] > 0 and rng.random() < 0.5:
                    expand_seq(item.items)
            elif isinstance(item, Star):
                while state["left"] > 0 and rng.random() < 0.4:
                    expand_seq(item.items)
            else:
                state["left"] -= 1
                alts = rules[item.name].alts
                if state["left"] <= 0:
                    lengths = [seq_len(a) for a in alts]
                    alts = tuple(a for a, n in zip(alts, lengths, strict=True) if n == min(lengths))
                expand_seq(rng.choice(alts))

        expand(Ref(self.root))
        return "".join(out)


def _refs_in_alts(alts: tuple[Seq, ...]) -> set[str]:
    found: set[str] = set()
    stack = [item for seq in alts for item in seq]
    while stack:
        item = stack.pop()
        if isinstance(item, Ref):
            found.add(item.name)
        elif isinstance(item, (Opt, Star)):
            stack.extend(item.items)
    return found


def _item_min(item: Item, lengths: dict[str, float]) -> float:
    if isinstance(item, Lit):
        return len(item.text)
    if isinstance(item, Chars):
        return 1
    if isinstance(item, Ref):
        return lengths[item.name]
    return 0  # Opt and Star may be empty


def _min_lengths(grammar: Grammar) -> dict[str, float]:
    """Shortest derivation length per rule, by fixpoint iteration from infinity."""
    lengths: dict[str, float] = {r.name: math.inf for r in grammar.rules}
    changed = True
    while changed:
        changed = False
        for rule in grammar.rules:
            value = min(sum(_item_min(i, lengths) for i in seq) for seq in rule.alts)
            if value < lengths[rule.name]:
                lengths[rule.name], changed = value, True
    return lengths


def _max_length(grammar: Grammar) -> float:
    """Longest derivation from the root; ``math.inf`` if a rule can reach itself or a
    non-empty ``Star`` is reachable (every rule of our grammars derives something)."""
    rules = grammar.by_name
    memo: dict[str, float] = {}
    on_stack: set[str] = set()

    def item_max(item: Item) -> float:
        if isinstance(item, Lit):
            return len(item.text)
        if isinstance(item, Chars):
            return 1
        if isinstance(item, Ref):
            return rule_max(item.name)
        inner = sum(item_max(i) for i in item.items)
        return math.inf if isinstance(item, Star) and inner > 0 else inner

    def rule_max(name: str) -> float:
        if name in on_stack:
            return math.inf
        if name not in memo:
            on_stack.add(name)
            memo[name] = max(sum(item_max(i) for i in seq) for seq in rules[name].alts)
            on_stack.discard(name)
        return memo[name]

    return rule_max(grammar.root)


def _seq_text(seq: Seq, name: dict[str, str], lit, chars) -> str:
    parts = []
    for item in seq:
        if isinstance(item, Lit):
            parts.append(lit(item.text))
        elif isinstance(item, Chars):
            parts.append(chars(item))
        elif isinstance(item, Ref):
            parts.append(name[item.name])
        else:
            inner = _seq_text(item.items, name, lit, chars)
            parts.append(f"({inner}){'?' if isinstance(item, Opt) else '*'}")
    return " ".join(parts) if parts else '""'


def _gbnf_name(name: str) -> str:
    # GBNF names take dashes, not underscores, and "root" is reserved for the start rule.
    name = name.replace("_", "-")
    return "root-rule" if name == "root" else name


def _escape(text: str) -> str:
    return text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n")


def _quote(text: str) -> str:
    # GBNF and Lark quote literals alike.
    return f'"{_escape(text)}"'


def _gbnf_chars(chars: Chars) -> str:
    return "[" + "".join(lo if lo == hi else f"{lo}-{hi}" for lo, hi in chars.ranges) + "]"


def _lark_chars(chars: Chars) -> str:
    return "/" + _gbnf_chars(chars) + "/"
