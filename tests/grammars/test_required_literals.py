"""Grammars that must write given literals: exactly the strings that do, unambiguously."""

import random

import lark
import pytest

from ara.grammars import Syntax, atoms, build_grammar, parse, require_literals, walk
from ara.grammars.ast import interval_of

from conftest import needs_llama

# (language, literals every string must write)
CASES = {
    "a proposition": (Syntax(aps=("a", "b"), intervals=True, bounds=(0, 3, 12, 250),
                             max_depth=3, max_args=2), ("b",)),
    "a proposition and a bound": (Syntax(aps=("a", "b"), intervals=True, max_args=2,
                                         bounds=(0, 3, 12, 250), max_depth=3), ("b", "12")),
    "the largest bound": (Syntax(aps=("a", "b"), intervals=True, bounds=(0, 3, 12, 250),
                                 max_depth=3), ("250",)),
    "two propositions, wide & and |": (Syntax(aps=("a", "b", "c"), max_depth=3, max_args=3),
                                       ("a", "c")),
    "relaxed layout, a name that starts with F": (
        Syntax(aps=("a", "b", "Fa"), intervals=True, max_bound=30, allow_inf=True,
               relaxed=True), ("Fa",)),
}


def writes(text: str, literals) -> bool:
    """Whether the formula ``text`` names each literal as a proposition or a bound."""
    formula = parse(text)
    bounds = set()
    for node in walk(formula):
        if (iv := interval_of(node)) is not None:
            bounds |= {str(iv.lo), str(iv.hi)}
    return all(lit in atoms(formula) or lit in bounds for lit in literals)


@pytest.fixture(scope="module", params=sorted(CASES))
def case(request):
    syntax, literals = CASES[request.param]
    plain = build_grammar(syntax).grammar
    required = require_literals(plain, literals)
    parser = lark.Lark(required.to_lark(), start="start", parser="earley", lexer="dynamic",
                       ambiguity="explicit")
    return syntax, literals, plain, required, parser


def test_it_admits_exactly_the_strings_that_write_the_literals(case):
    """Tests Lark on the required grammar against the parser, on 400 strings of the
    plain language (both kinds: with and without the literals)."""
    _, literals, plain, _, parser = case
    rng = random.Random(0)
    kinds = set()
    for _ in range(400):
        text = plain.sample(rng, budget=rng.randint(1, 30))
        try:
            parser.parse(text)
            accepted = True
        except lark.exceptions.LarkError:
            accepted = False
        assert accepted == writes(text, literals), text
        kinds.add(accepted)
    assert kinds == {True, False}


def test_every_string_it_derives_writes_the_literals(case):
    """Tests the other direction: its samples are in the plain language and name all."""
    syntax, literals, _, required, _ = case
    rng = random.Random(1)
    for _ in range(300):
        text = required.sample(rng, budget=rng.randint(1, 30))
        assert syntax.accepts(text) and writes(text, literals), text


def test_it_stays_unambiguous(case):
    """Tests that each string has one derivation, as in the plain grammar: a decoder's
    parse stacks do not multiply."""
    _, _, _, required, parser = case
    rng = random.Random(2)
    for _ in range(150):
        tree = parser.parse(required.sample(rng, budget=rng.randint(1, 30)))
        assert not list(tree.find_data("_ambig"))


def test_it_keeps_the_termination_bound():
    """Tests that a bounded grammar stays bounded, by no more than the plain one."""
    syntax, literals = CASES["a proposition and a bound"]
    plain = build_grammar(syntax).grammar
    assert require_literals(plain, literals).max_length() <= plain.max_length() < float("inf")


def test_a_literal_the_grammar_never_writes_is_an_error():
    plain = build_grammar(Syntax(aps=("a", "b"), intervals=True, bounds=(0, 5))).grammar
    with pytest.raises(ValueError, match="never writes '7'"):
        require_literals(plain, ["7"])
    with pytest.raises(ValueError, match="never writes 'c'"):
        require_literals(plain, ["a", "c"])


def test_a_depth_too_small_for_all_literals_is_an_error():
    """Tests that depth 1 (one operator over atoms) cannot name three propositions."""
    plain = build_grammar(Syntax(aps=("a", "b", "c"), max_depth=1, max_args=2)).grammar
    assert require_literals(plain, ["a", "b"]).sample(random.Random(0))
    with pytest.raises(ValueError, match="never writes .c."):
        require_literals(plain, ["a", "b", "c"])


@needs_llama
def test_llama_cpp_reads_the_gbnf_and_agrees():
    """Tests llama.cpp's grammar engine on the emitted GBNF (it rejects left recursion
    and unknown rules) against the parser, on strings of the plain language."""
    from ara.eval.translate.llama_check import LlamaGrammarChecker

    syntax, literals = CASES["a proposition and a bound"]
    plain = build_grammar(syntax).grammar
    checker = LlamaGrammarChecker(require_literals(plain, literals).to_gbnf())
    rng = random.Random(3)
    for _ in range(150):
        text = plain.sample(rng, budget=rng.randint(1, 25))
        assert checker.accepts(text) == writes(text, literals), text
