"""Recursive-descent parser of the STL surface syntax.

Precedence, loosest first (all binary operators but ``<->`` associate as noted)::

    <->   non-associative: ``a <-> b <-> c`` is an error, write parentheses
    ->    right-associative: ``a -> b -> c`` is ``a -> (b -> c)``
    |     n-ary: ``a | b | c`` is one Or with three arguments
    &     n-ary
    U     right-associative, with an optional interval: ``a U[2,5] b``
    ! ~ F G X   prefix, tightest: ``F a & b`` is ``(F a) & b``

``F`` and ``G`` take an optional interval ``[lo,hi]`` (``hi`` may be ``inf``);
``X`` takes none. Parentheses may surround any subformula.
"""

from __future__ import annotations

from ara.errors import STLSyntaxError
from ara.grammars.ast import (
    KEYWORDS,
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
from ara.grammars.lexer import Kind, Token, tokenize

#: Deepest nesting the parser reads, counted twice: operators inside operators (prefix
#: operators, chained ``U`` and ``->``), and parentheses inside parentheses. NL2TL's
#: formulas nest at most 7 deep and decoding grammars 5. The bound keeps the parser and
#: every recursive walk of a tree far from Python's recursion limit, so deeper input
#: gets an error instead of a ``RecursionError``; and since the printer adds at most
#: one level of parentheses per operator, whatever parses also parses once printed.
MAX_NESTING = 64


def parse(text: str) -> Formula:
    """Parse a formula, accepting any whitespace and both ``!`` and ``~``.

    Args:
        text: A formula such as ``"F(a) & G[0,30](!b)"``.

    Returns:
        The formula's tree.

    Raises:
        STLSyntaxError: Naming the position of the first token that does not fit.
    """
    return parse_tokens(text, tokenize(text))


def parse_tokens(text: str, tokens: list[Token]) -> Formula:
    """Parse already-lexed ``tokens`` of ``text`` (see :func:`parse`)."""
    parser = _Parser(text, tokens)
    formula = parser.iff()
    parser.expect_end()
    return formula


class _Parser:
    def __init__(self, text: str, tokens: list[Token]) -> None:
        self.text = text
        self.tokens = tokens
        self.i = 0
        self.nesting = {"operators": 0, "parentheses": 0}

    def nested(self, parse_inner, kind: str = "operators"):
        """``parse_inner()`` one level deeper in ``kind``, refusing to pass the bound."""
        if self.nesting[kind] >= MAX_NESTING:
            raise STLSyntaxError(
                self.text, self.tok.start,
                f"the formula nests more than {MAX_NESTING} {kind} deep (the parser's "
                "bound); write it flatter",
            )
        self.nesting[kind] += 1
        try:
            return parse_inner()
        finally:
            self.nesting[kind] -= 1

    @property
    def tok(self) -> Token:
        return self.tokens[self.i]

    def at(self, *texts: str) -> bool:
        return self.tok.kind in (Kind.WORD, Kind.PUNCT) and self.tok.text in texts

    def advance(self) -> Token:
        token = self.tok
        self.i += 1
        return token

    def fail(self, expected: str) -> STLSyntaxError:
        found = "end of input" if self.tok.kind is Kind.END else repr(self.tok.text)
        return STLSyntaxError(self.text, self.tok.start, f"expected {expected}, found {found}")

    def expect(self, text: str) -> Token:
        if not self.at(text):
            raise self.fail(repr(text))
        return self.advance()

    def expect_end(self) -> None:
        if self.tok.kind is not Kind.END:
            if self.at("<->"):
                raise STLSyntaxError(
                    self.text, self.tok.start,
                    "'<->' does not chain; add parentheses, e.g. (a <-> b) <-> c",
                )
            raise self.fail("an operator or end of input")

    # One method per precedence level, loosest first.
    def iff(self) -> Formula:
        lhs = self.implies()
        if self.at("<->"):
            self.advance()
            return Iff(lhs, self.implies())
        return lhs

    def implies(self) -> Formula:
        lhs = self.disjunction()
        if self.at("->"):
            self.advance()
            return Implies(lhs, self.nested(self.implies))
        return lhs

    def disjunction(self) -> Formula:
        args = [self.conjunction()]
        while self.at("|"):
            self.advance()
            args.append(self.conjunction())
        return args[0] if len(args) == 1 else Or(tuple(args))

    def conjunction(self) -> Formula:
        args = [self.until()]
        while self.at("&"):
            self.advance()
            args.append(self.until())
        return args[0] if len(args) == 1 else And(tuple(args))

    def until(self) -> Formula:
        lhs = self.unary()
        if self.at("U"):
            self.advance()
            interval = self.interval() if self.at("[") else None
            return Until(lhs, self.nested(self.until), interval)
        return lhs

    def unary(self) -> Formula:
        if self.at("!", "~"):
            self.advance()
            return Not(self.nested(self.unary))
        if self.at("F", "G"):
            op = self.advance().text
            interval = self.interval() if self.at("[") else None
            arg = self.nested(self.unary)
            return Eventually(arg, interval) if op == "F" else Always(arg, interval)
        if self.at("X"):
            self.advance()
            if self.at("["):
                raise self.fail("a formula after X (X takes no interval; nest X or use F[a,b])")
            return Next(self.nested(self.unary))
        return self.primary()

    def primary(self) -> Formula:
        if self.at("("):
            self.advance()
            inner = self.nested(self.iff, "parentheses")
            if not self.at(")"):
                if self.at("<->"):
                    self.expect_end()
                raise self.fail("')' or an operator")
            self.advance()
            return inner
        if self.at("true", "false"):
            return Const(self.advance().text == "true")
        if self.tok.kind is Kind.WORD and self.tok.text not in KEYWORDS:
            return Atom(self.advance().text)
        if self.tok.kind is Kind.WORD and self.tok.text in ("U", "inf"):
            raise self.fail(f"a formula ({self.tok.text!r} is reserved)")
        raise self.fail("a formula (an atomic proposition, true, false, '(' or a prefix operator)")

    def interval(self) -> Interval:
        self.expect("[")
        lo = self.number()
        self.expect(",")
        if self.at("inf"):
            self.advance()
            hi = None
        else:
            start = self.tok.start
            hi = self.number()
            if hi < lo:
                raise STLSyntaxError(
                    self.text, start, f"interval upper bound {hi} is below its lower bound {lo}"
                )
        self.expect("]")
        return Interval(lo, hi)

    def number(self) -> int:
        if self.tok.kind is not Kind.NUMBER:
            raise self.fail("a non-negative integer")
        return int(self.advance().text)
