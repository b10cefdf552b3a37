"""Fuzzing the parser and printer: whatever the input, the answer is a formula or the
project's own syntax error, never a traceback, and printing is stable."""

import random

import pytest

from ara.errors import STLSyntaxError
from ara.grammars import parse, to_text
from ara.grammars.parser import MAX_NESTING

# Tokens of the language, near-misses of it, and plain noise.
PIECES = ["a", "b", "prop_1", "go_to_kitchen", "true", "false", "inf", "F", "G", "X", "U",
          "!", "~", "&", "|", "->", "<->", "-", "<", ">", "(", ")", "[", "]", ",", " ", "  ",
          "0", "3", "12", "007", "1000", "99999999999999999999", "[0,5]", "[5,0]", "[2,inf]",
          "\t", "\n", "é", "∧", "#", ".", "__", "F(", "G[", "U[1,2]", ")(", "_"]


def random_text(rng: random.Random) -> str:
    if rng.random() < 0.2:  # raw characters, printable or not
        return "".join(chr(rng.randrange(0, 0x250)) for _ in range(rng.randrange(0, 12)))
    return "".join(rng.choice(PIECES) for _ in range(rng.randrange(0, 14)))


def check(text: str) -> bool:
    """Parse; on success, print -> parse -> print must be the identity."""
    try:
        formula = parse(text)
    except STLSyntaxError:
        return False
    printed = to_text(formula)
    assert parse(printed) == formula, text
    assert to_text(parse(printed)) == printed, text
    return True


def test_one_hundred_thousand_random_strings_give_formulas_or_syntax_errors():
    rng = random.Random(0)
    accepted = sum(check(random_text(rng)) for _ in range(100_000))
    assert 1_000 < accepted < 99_000  # both outcomes are exercised


DEEP = {
    "parentheses": lambda n: "(" * n + "a" + ")" * n,
    "negations": lambda n: "!" * n + "a",
    "prefix operators": lambda n: "F(" * n + "a" + ")" * n,
    "printed until": lambda n: "a U (" * n + "b" + ")" * n,
    "timed prefix": lambda n: "G[0,5] " * n + "a",
    "chained until": lambda n: " U ".join(["a"] * n) + " U b",
    "chained implication": lambda n: "a -> " * n + "b",
    "unclosed": lambda n: "(" * n,
    "long conjunction": lambda n: " & ".join(["a"] * n),
}


@pytest.mark.parametrize("shape", sorted(DEEP))
@pytest.mark.parametrize("n", [10, MAX_NESTING - 1, MAX_NESTING + 1, 1_000, 10_000])
def test_deep_nesting_parses_up_to_the_bound_and_is_refused_beyond(shape, n):
    text = DEEP[shape](n)
    if shape == "long conjunction":  # flat: no nesting, any length
        assert check(text)
    elif shape == "unclosed" or n > MAX_NESTING:
        with pytest.raises(STLSyntaxError):
            parse(text)
    else:
        assert check(text)
