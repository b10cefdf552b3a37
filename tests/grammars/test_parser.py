"""The parser and printer: precedence, associativity, errors, round trips."""

import pytest
from hypothesis import given, settings

from ara.errors import STLSyntaxError
from ara.grammars import (
    Always,
    And,
    Atom,
    Eventually,
    Iff,
    Implies,
    Interval,
    Not,
    Or,
    Until,
    parse,
    to_text,
)

from conftest import formulas

a, b, c, d = Atom("a"), Atom("b"), Atom("c"), Atom("d")


@pytest.mark.parametrize(
    ("text", "tree"),
    [
        ("F(a) & G(!b)", And((Eventually(a), Always(Not(b))))),  # the paper's style
        ("F(a) & G(~b)", And((Eventually(a), Always(Not(b))))),  # ~ is also negation
        ("a | b & c", Or((a, And((b, c))))),  # & binds tighter than |
        ("a & b | c", Or((And((a, b)), c))),
        ("a -> b | c", Implies(a, Or((b, c)))),  # | binds tighter than ->
        ("a -> b -> c", Implies(a, Implies(b, c))),  # -> is right-associative
        ("a <-> b -> c", Iff(a, Implies(b, c))),  # <-> is loosest
        ("a U b U c", Until(a, Until(b, c))),  # U is right-associative
        ("a & b U c", And((a, Until(b, c)))),  # U binds tighter than &
        ("F a U b", Until(Eventually(a), b)),  # prefix operators bind tightest
        ("!a U b", Until(Not(a), b)),
        ("a & b & c", And((a, b, c))),  # chains are n-ary
        ("(a & b) & c", And((And((a, b)), c))),  # parentheses keep their grouping
        ("F[2,5](a)", Eventually(a, Interval(2, 5))),
        ("G[0,30](a)", Always(a, Interval(0, 30))),
        ("a U[2,5] b", Until(a, b, Interval(2, 5))),
        ("F[3,inf] a", Eventually(a, Interval(3, None))),  # unbounded upper end
        ("  F ( a )\n", Eventually(a)),  # any whitespace
        ("(((a)))", a),  # parentheses anywhere
    ],
)
def test_parse_reads_precedence_and_associativity(text, tree):
    """Tests that the documented precedence and associativity hold."""
    assert parse(text) == tree


@pytest.mark.parametrize(
    ("text", "position", "message"),
    [
        ("F(a & ", 6, "found end of input"),  # unfinished
        ("a && b", 3, "expected a formula"),  # doubled operator
        ("a <-> b <-> c", 8, "does not chain"),  # <-> needs parentheses
        ("F[5,2](a)", 4, "below its lower bound"),  # reversed interval
        ("X[1,2] a", 1, "X takes no interval"),
        ("a $ b", 2, "unexpected character"),  # unknown operator
        ("a U", 3, "expected a formula"),
        ("F(a))", 4, "expected an operator or end of input"),
        ("true U inf", 7, "'inf' is reserved"),
    ],
)
def test_parse_errors_name_the_position(text, position, message):
    """Tests that invalid formulas raise STLSyntaxError pointing at the offending token."""
    with pytest.raises(STLSyntaxError, match=message) as info:
        parse(text)
    assert info.value.position == position


def test_syntax_error_is_a_value_error():
    """Tests that callers may catch the builtin ValueError."""
    with pytest.raises(ValueError):
        parse("(")


@pytest.mark.parametrize(
    ("tree", "text"),
    [
        (And((Eventually(a), Always(Not(b)))), "F(a) & G(!b)"),
        (Not(And((a, b))), "!(a & b)"),
        (Not(Eventually(a)), "!F(a)"),
        (Implies(Or((a, b)), c), "(a | b) -> c"),
        (Until(a, And((b, c)), Interval(2, 5)), "a U[2,5] (b & c)"),
        (And((And((a, b)), c)), "(a & b) & c"),
        (Eventually(a, Interval(0, None)), "F[0,inf](a)"),
    ],
)
def test_printer_writes_canonical_form(tree, text):
    """Tests the canonical layout on hand-written cases."""
    assert to_text(tree) == text


@settings(max_examples=300, deadline=None)
@given(formulas(timed=True, allow_next=True, allow_inf=True))
def test_printed_formulas_parse_back_to_the_same_tree(tree):
    """Tests that parse(to_text(f)) == f for random trees."""
    assert parse(to_text(tree)) == tree


@settings(max_examples=200, deadline=None)
@given(formulas(timed=True))
def test_canonical_text_is_a_fixed_point(tree):
    """Tests that printing a parsed canonical text gives the same text."""
    text = to_text(tree)
    assert to_text(parse(text)) == text
