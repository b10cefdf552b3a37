"""The grammar IR: number ranges, emitters, lengths, provenance."""

import re

import pytest

from ara.errors import ConfigError
from ara.grammars import GRAMMAR_VERSION, Syntax, build_grammar
from ara.grammars.grammar_ir import Chars, Lit
from ara.grammars.stl_grammar import number_patterns

from conftest import needs_llama


def _matches(pattern, text):
    if len(pattern) != len(text):
        return False
    for item, ch in zip(pattern, text, strict=True):
        if isinstance(item, Lit) and item.text != ch:
            return False
        if isinstance(item, Chars) and ch not in item.members():
            return False
    return True


@pytest.mark.parametrize(("lo", "hi"), [(0, 0), (0, 9), (3, 7), (7, 123), (10, 99), (0, 1000),
                                        (99, 101), (456, 951)])
def test_number_patterns_match_exactly_the_range(lo, hi):
    """Tests every numeral 0..1200 (and leading-zero forms) against the patterns."""
    patterns = number_patterns(lo, hi)
    for n in range(0, 1201):
        assert any(_matches(p, str(n)) for p in patterns) == (lo <= n <= hi), n
        assert not any(_matches(p, "0" + str(n)) for p in patterns)


def test_emitted_texts_name_each_rule_once():
    """Tests the GBNF and Lark texts: one line per rule, start rules named as each needs."""
    grammar = build_grammar(Syntax(aps=("a", "b"), intervals=True, max_bound=20)).grammar
    gbnf, lark = grammar.to_gbnf(), grammar.to_lark()
    assert re.search(r"^root ::= ", gbnf, re.M) and re.search(r"^start: ", lark, re.M)
    assert len(gbnf.splitlines()) == len(lark.splitlines()) == len(grammar.rules)
    assert "_" not in "".join(line.split(" ::= ")[0] for line in gbnf.splitlines())


def test_grammar_provenance_records_version_and_hash():
    """Tests what outputs record about the grammar they used."""
    built = build_grammar(Syntax(aps=("a", "b")))
    prov = built.provenance()
    assert prov["grammar_version"] == GRAMMAR_VERSION
    assert prov["grammar_sha256"] == built.grammar.sha256() and len(prov["grammar_sha256"]) == 64
    assert prov["syntax"]["aps"] == ["a", "b"]
    assert build_grammar(Syntax(aps=("a", "c"))).sha256 != built.sha256


def test_min_length_is_the_shortest_formula():
    """Tests min_lengths: the shortest canonical formula over {a} is 'a'."""
    grammar = build_grammar(Syntax(aps=("a",))).grammar
    assert grammar.min_lengths()["root"] == 1


def test_huge_bounds_are_refused_before_building():
    """Tests that an interval bound past MAX_GRAMMAR_BOUND fails fast with the fix."""
    with pytest.raises(ConfigError, match="Rescale the time unit"):
        build_grammar(Syntax(aps=("a",), intervals=True, max_bound=10**7))


def test_grammar_needs_propositions():
    """Tests that a grammar is built per request, from its propositions."""
    with pytest.raises(ConfigError, match="give aps"):
        build_grammar(Syntax())


@needs_llama
def test_with_suffix_adds_exactly_the_suffix_newlines_included():
    """Tests the decoding grammar ' ' + formula + newline: both formats escape the
    newline, and a formula without it, or with anything after it, is refused."""
    import lark

    from ara.eval.translate.llama_check import LlamaGrammarChecker

    grammar = build_grammar(Syntax(aps=("a", "b"))).grammar.with_prefix(" ").with_suffix("\n")
    assert '"\\n"' in grammar.to_gbnf() and '"\\n"' in grammar.to_lark()
    parser = lark.Lark(grammar.to_lark(), start="start", parser="earley", lexer="dynamic")
    parser.parse(" F(a) & b\n")
    for bad in (" F(a) & b", " F(a) & b\n\n", " F(a)\n & b"):
        with pytest.raises(lark.exceptions.LarkError):
            parser.parse(bad)
    assert grammar.min_lengths()[grammar.root] == 3
    checker = LlamaGrammarChecker(grammar.to_gbnf())
    assert checker.accepts(" F(a) & b\n") and not checker.accepts(" F(a) & b")


def test_with_prefix_adds_exactly_the_prefix():
    """Tests the decoding grammar ' ' + formula in both emitted formats."""
    import lark

    grammar = build_grammar(Syntax(aps=("a", "b"))).grammar.with_prefix(" ")
    gbnf = grammar.to_gbnf()
    assert gbnf.count("root ::= ") == 1 and 'root ::= " " root-rule' in gbnf
    parser = lark.Lark(grammar.to_lark(), start="start", parser="earley", lexer="dynamic")
    parser.parse(" F(a) & b")
    with pytest.raises(lark.exceptions.LarkError):
        parser.parse("F(a) & b")
    assert grammar.min_lengths()[grammar.root] == 2
