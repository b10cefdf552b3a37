"""Language membership: which strings each layout admits, and the errors for the rest."""

import pytest

from ara.errors import ConfigError, STLSyntaxError
from ara.grammars import Syntax

CANONICAL = Syntax(aps=("a", "b"), intervals=True, max_bound=50)
RELAXED = Syntax(aps=("a", "b"), intervals=True, max_bound=50, relaxed=True)


@pytest.mark.parametrize(
    ("text", "canonical", "relaxed"),
    [
        ("F(a) & G(!b)", True, True),  # canonical text is relaxed text too
        ("F a & G !b", False, True),  # precedence instead of parentheses
        ("F(a)&G(~b)", False, True),  # optional spaces, ~ for not
        ("Fa", False, False),  # one word 'Fa', not F applied to a
        ("F  a", False, False),  # at most one space
        ("a U b", True, True),
        ("a U(b)", False, False),  # U needs spaces on both sides
        ("a U[2,5] b", True, True),
        ("a U [2,5] b", False, False),  # no space before an interval
        ("F[2, 5](a)", False, False),  # no space inside it
        ("F[2,51](a)", False, False),  # beyond max_bound
        ("F[02,5](a)", False, False),  # no leading zeros
        (" a", False, False),  # no leading or trailing whitespace
        ("(a & b) | c", False, False),  # c is not a proposition of this request
        ("((a))", False, True),  # redundant parentheses
        ("a & b & a", True, True),
        ("a <-> b", True, True),
    ],
)
def test_membership_by_layout(text, canonical, relaxed):
    """Tests which strings the canonical and the relaxed layouts admit."""
    assert CANONICAL.accepts(text) is canonical
    assert RELAXED.accepts(text) is relaxed


@pytest.mark.parametrize(
    ("syntax", "text", "message"),
    [
        (CANONICAL, "F(c)", "unknown atomic proposition 'c'; allowed: a, b"),
        (Syntax(aps=("a",)), "F[1,2](a)", "intervals are not allowed"),
        (CANONICAL, "F[1,99](a)", "exceeds max_bound=50"),
        (CANONICAL, "F[1,inf](a)", r"unbounded intervals \[lo,inf\] are not allowed"),
        (CANONICAL, "X(a)", "X is not allowed"),
        (CANONICAL, "a&b", "not in canonical form 'a & b'"),
        (Syntax(aps=("a",), max_depth=2), "F(F(F(a)))", "depth 3 exceeds max_depth=2"),
        (Syntax(aps=("a",), max_args=2), "a & a & a", "3 arguments exceeds max_args=2"),
        (RELAXED, "a  & b", "at most one space"),
    ],
)
def test_rejections_say_which_rule(syntax, text, message):
    """Tests that each rejected string names the rule it breaks."""
    with pytest.raises(STLSyntaxError, match=message):
        syntax.check(text)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        (dict(aps=()), "non-empty"),
        (dict(aps="ab"), "non-empty sequence"),  # a string is not a list of names
        (dict(aps=("F",)), "not a valid name"),  # keywords cannot be propositions
        (dict(aps=("go-to",)), "not a valid name"),
        (dict(max_bound=-1), "max_bound must be an integer >= 0"),
        (dict(max_depth=0), "max_depth must be a whole number >= 1"),
        (dict(max_depth=2.5), "max_depth must be a whole number >= 1"),
        (dict(max_args=1), "max_args must be a whole number >= 2"),
        # What shapes intervals shapes nothing without them (ara grammar refuses it too).
        (dict(allow_inf=True), "set intervals=True"),
        (dict(bounds=(0, 5)), "set intervals=True"),
        (dict(relaxed=True, max_depth=3), "canonical layout only"),
    ],
)
def test_bad_options_are_refused(kwargs, message):
    """Tests Syntax's own checks on construction."""
    with pytest.raises(ConfigError, match=message):
        Syntax(**kwargs)


def test_duplicate_propositions_are_merged_in_order():
    """Tests that repeated names collapse without reordering."""
    assert Syntax(aps=("b", "a", "b")).aps == ("b", "a")
