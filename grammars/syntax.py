"""The language a grammar describes, and exact membership in it.

A :class:`Syntax` fixes one language: which atomic propositions, whether intervals
(and up to which bound) are allowed, and how strict the layout is. The grammar
builder (:mod:`ara.grammars.stl_grammar`) emits a grammar for exactly this
language; :meth:`Syntax.check` decides membership with the shared parser, so that
*a string is in the grammar's language if and only if* ``check`` accepts it. The
property tests in ``tests/grammars/test_grammar_exactness.py`` hold both to that.

Two layouts:

* canonical (``relaxed=False``): only the printer's own output
  (:mod:`ara.grammars.printer`). This is what constrained decoding uses: one
  spelling per formula, and with ``max_depth`` and ``max_args`` set the language is
  finite, so every generation ends within ``grammar.max_length()`` characters.
* relaxed (``relaxed=True``), as in the paper: precedence instead of mandatory
  parentheses, redundant parentheses, ``!`` or ``~``, and at most one space between
  tokens; one space is required between two words, and around ``U``.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from itertools import pairwise

from ara.errors import ConfigError, STLSyntaxError
from ara.grammars.ast import KEYWORDS, And, Formula, Or, depth, is_identifier, walk
from ara.grammars.lexer import Kind, Token, tokenize
from ara.grammars.parser import parse_tokens
from ara.grammars.printer import to_text

#: Bumped whenever the grammar a given Syntax produces changes.
GRAMMAR_VERSION = "1.0.0"
#: The language the translator decodes in by default and the synthetic generator writes
#: in: nesting depth and arguments of one & or |. NL2TL needs depth 4 and two arguments
#: (``(a & b) & c`` nests), and two keep the longest answer, hence the token budget, short.
DECODING_MAX_DEPTH = 5
DECODING_MAX_ARGS = 2


@dataclass(frozen=True)
class Syntax:
    """Options that pick one STL language.

    Args:
        aps: The atomic propositions allowed, or ``None`` for any identifier (a
            grammar can only be built when they are given).
        intervals: Whether ``F``, ``G`` and ``U`` may carry ``[lo,hi]``.
        max_bound: Largest number allowed in an interval, ``>= 0``. Default 1000.
        bounds: With ``intervals``: the only numbers an interval may use (each
            ``<= max_bound``), e.g. those an instruction writes and 0; ``None``: every
            number up to ``max_bound``. A handful of numbers makes a grammar of a few
            rules instead of two per number up to ``max_bound``.
        allow_inf: Whether ``[lo,inf]`` is allowed.
        allow_next: Whether ``X`` is allowed (NL2TL formulas never use it).
        relaxed: Paper-style layout instead of the canonical one (see module doc).
        max_depth: Canonical layout only: largest operator nesting depth, ``>= 1``.
        max_args: Canonical layout only: most arguments of one ``&`` or ``|``, ``>= 2``.
    """

    aps: tuple[str, ...] | None = None
    intervals: bool = False
    max_bound: int = 1000
    bounds: tuple[int, ...] | None = None
    allow_inf: bool = False
    allow_next: bool = False
    relaxed: bool = False
    max_depth: int | None = None
    max_args: int | None = None

    def __post_init__(self) -> None:
        if self.aps is not None:
            if isinstance(self.aps, str) or not self.aps:
                raise ConfigError(f"aps must be a non-empty sequence of names, got {self.aps!r}")
            object.__setattr__(self, "aps", tuple(dict.fromkeys(self.aps)))
            for name in self.aps:
                if not is_identifier(name) or name in KEYWORDS:
                    raise ConfigError(
                        f"atomic proposition {name!r} is not a valid name: use "
                        f"[A-Za-z_][A-Za-z0-9_]* and none of {', '.join(sorted(KEYWORDS))}"
                    )
        if not isinstance(self.max_bound, int) or self.max_bound < 0:
            raise ConfigError(f"max_bound must be an integer >= 0, got {self.max_bound!r}")
        if self.bounds is not None:
            bounds = tuple(sorted(set(self.bounds)))
            if not bounds or not all(isinstance(b, int) and 0 <= b <= self.max_bound
                                     for b in bounds):
                raise ConfigError(f"bounds must be a non-empty set of integers in "
                                  f"0..max_bound={self.max_bound}, got {self.bounds!r}")
            object.__setattr__(self, "bounds", bounds)
        if not self.intervals and (self.allow_inf or self.bounds is not None):
            # Else they would be dropped silently, and the grammar cached and recorded
            # under settings that do not shape it.
            raise ConfigError("allow_inf and bounds shape intervals: set intervals=True")
        for name, low in (("max_depth", 1), ("max_args", 2)):
            value = getattr(self, name)
            if value is not None and (not isinstance(value, int) or isinstance(value, bool)
                                      or value < low):
                raise ConfigError(f"{name} must be a whole number >= {low} or None, "
                                  f"got {value!r}")
        if self.relaxed and (self.max_depth is not None or self.max_args is not None):
            raise ConfigError(
                "max_depth and max_args bound the canonical layout only; "
                "set relaxed=False to bound the language"
            )

    def to_dict(self) -> dict:
        """Plain-JSON form, for recording in the outputs that used this language."""
        data = asdict(self)
        data["aps"] = list(self.aps) if self.aps is not None else None
        data["bounds"] = list(self.bounds) if self.bounds is not None else None
        return data

    def accepts(self, text: str) -> bool:
        """Whether ``text`` belongs to this language."""
        try:
            self.check(text)
        except STLSyntaxError:
            return False
        return True

    def check(self, text: str) -> Formula:
        """Parse ``text`` and verify it belongs to this language.

        Returns:
            The formula's tree.

        Raises:
            STLSyntaxError: Naming the position and the rule that ``text`` breaks.
        """
        tokens = tokenize(text)
        formula = parse_tokens(text, tokens)
        self._check_tokens(text, tokens)
        if self.relaxed:
            _check_relaxed_layout(text, tokens)
        else:
            canonical = to_text(formula)
            if canonical != text:
                pairs = enumerate(zip(text, canonical, strict=False))
                at = next((i for i, (a, b) in pairs if a != b), min(len(text), len(canonical)))
                raise STLSyntaxError(text, at, f"not in canonical form {canonical!r}")
            self._check_shape(text, formula)
        return formula

    def _check_tokens(self, text: str, tokens: list[Token]) -> None:
        """Vocabulary rules shared by both layouts, checked token by token."""
        allowed = set(self.aps) if self.aps is not None else None
        for tok in tokens:
            if tok.kind is Kind.WORD and tok.text not in KEYWORDS and allowed is not None:
                if tok.text not in allowed:
                    raise STLSyntaxError(
                        text, tok.start,
                        f"unknown atomic proposition {tok.text!r}; allowed: {', '.join(self.aps)}",
                    )
            elif tok.text == "[" and not self.intervals:
                raise STLSyntaxError(text, tok.start, "intervals are not allowed in this language")
            elif tok.text == "inf" and not self.allow_inf:
                raise STLSyntaxError(
                    text, tok.start, "unbounded intervals [lo,inf] are not allowed"
                )
            elif tok.text == "X" and not self.allow_next:
                raise STLSyntaxError(text, tok.start, "the next operator X is not allowed")
            elif tok.kind is Kind.NUMBER:
                if tok.text != str(int(tok.text)):
                    raise STLSyntaxError(
                        text, tok.start, f"write {int(tok.text)}, without leading zeros"
                    )
                if int(tok.text) > self.max_bound:
                    raise STLSyntaxError(
                        text, tok.start, f"time bound {tok.text} exceeds max_bound={self.max_bound}"
                    )
                if self.bounds is not None and int(tok.text) not in self.bounds:
                    raise STLSyntaxError(
                        text, tok.start,
                        f"time bound {tok.text} is not one of {', '.join(map(str, self.bounds))}"
                    )

    def _check_shape(self, text: str, formula: Formula) -> None:
        if self.max_depth is not None and depth(formula) > self.max_depth:
            raise STLSyntaxError(
                text, 0, f"nesting depth {depth(formula)} exceeds max_depth={self.max_depth}"
            )
        if self.max_args is not None:
            nary = (len(n.args) for n in walk(formula) if isinstance(n, (And, Or)))
            widest = max(nary, default=0)
            if widest > self.max_args:
                raise STLSyntaxError(
                    text, 0, f"an & or | with {widest} arguments exceeds max_args={self.max_args}"
                )


def _check_relaxed_layout(text: str, tokens: list[Token]) -> None:
    """Whitespace rules of the relaxed layout (the grammar's ``ws`` placements)."""
    if tokens[0].space:
        raise STLSyntaxError(text, 0, "no whitespace is allowed before the formula")
    in_interval = False
    after_until = False  # inside or right after U's interval, the next gap must be " "
    for prev, tok in pairwise(tokens):
        gap, at = tok.space, tok.start - len(tok.space)
        if tok.kind is Kind.END:
            if gap:
                raise STLSyntaxError(text, at, "no whitespace is allowed after the formula")
            return
        if gap not in ("", " "):
            raise STLSyntaxError(text, at, "use at most one space between tokens")
        if prev.text == "[":
            in_interval = True
        needs_space = (
            (prev.kind is Kind.WORD and tok.kind is Kind.WORD)
            or tok.text == "U"
            or (after_until and not in_interval and tok.text != "[")
        )
        no_space = tok.text == "[" or in_interval
        if needs_space and gap != " ":
            raise STLSyntaxError(text, tok.start, f"put one space before {tok.text!r}")
        if no_space and gap:
            raise STLSyntaxError(text, at, "no whitespace is allowed in or before an interval")
        if tok.text == "]":
            in_interval = False
        if tok.text == "U":
            after_until = True
        elif not in_interval and tok.text not in ("[", "]"):
            after_until = False
