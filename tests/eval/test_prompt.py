"""The prompt layout shared by evaluation and training."""

import random

from ara.eval.translate.prompt import (
    INSTRUCTIONS,
    Shot,
    build_prompt,
    format_example,
    grammar_for_prompt,
    sample_shots,
)
from ara.grammars import Syntax


def test_example_block_and_open_query():
    """Tests one worked example and the query the model completes."""
    assert format_example("go to a", ["a"], "F(a)") == "NL: go to a\nPropositions: a\nSTL: F(a)\n\n"
    assert format_example("go to a", ["a"]).endswith("STL:")


def test_prompts_share_everything_but_the_query():
    """Tests that two queries with the same shots share a prefix up to the query."""
    shots = [Shot("go to a", ("a",), "F(a)")]
    p1 = build_prompt("stay at b", ["b"], shots)
    p2 = build_prompt("never a", ["a"], shots)
    common = len(INSTRUCTIONS) + len(format_example("go to a", ["a"], "F(a)"))
    assert p1[:common + 1] == p2[:common + 1]
    assert p1.endswith("NL: stay at b\nPropositions: b\nSTL:")


def test_grammar_in_prompt_summarizes_intervals():
    """Tests that variant P shows a readable grammar, not the interval digit trie."""
    text = grammar_for_prompt(Syntax(aps=("a", "b"), intervals=True, max_bound=500))
    assert 'interval ::= "[" lo "," hi "]"  # integers, 0 <= lo <= hi <= 500' in text
    assert "lo-1" not in text and len(text.splitlines()) < 12
    assert build_prompt("x", ["a"], [], text).count("GBNF") == 1


def test_shots_are_drawn_without_repeats():
    """Tests sample_shots on a seeded draw."""
    from ara.data.normalize import Record

    pool = [Record(str(i), f"nl {i}", "a", ("a",), "navi", "lifted", i) for i in range(10)]
    shots = sample_shots(pool, 5, random.Random(0))
    assert len({s.nl for s in shots}) == 5
    assert shots == sample_shots(pool, 5, random.Random(0))
