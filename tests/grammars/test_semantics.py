"""The brute-force evaluator on lasso words, by hand."""

import pytest

from ara.grammars import parse
from ara.grammars.semantics import Lasso, holds

A, B, AB, NONE = frozenset("a"), frozenset("b"), frozenset("ab"), frozenset()
# a, b, then {a, b} forever
WORD = Lasso((A, B), (AB,))


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("a", True),
        ("b", False),
        ("X(b)", True),
        ("F[1,1](b)", True),
        ("F[0,0](b)", False),
        ("G[2,inf](a & b)", True),  # the loop holds both forever
        ("G(a)", False),  # step 1 lacks a
        ("a U b", True),  # b at step 1, a before it
        ("a U[2,3] b", False),  # a fails at step 1, before the window opens
        ("(a | b) U[2,3] b", True),
        ("F(G(a & b))", True),
    ],
)
def test_holds_on_a_hand_written_word(text, expected):
    """Tests each operator on the word a; b; (a&b)^omega."""
    assert holds(parse(text), WORD) is expected


def test_lasso_needs_a_loop():
    """Tests that an empty loop (a finite word) is refused."""
    with pytest.raises(ValueError, match="non-empty loop"):
        Lasso((A,), ())
