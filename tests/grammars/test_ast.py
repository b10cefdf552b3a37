"""The tree: construction checks and the helpers over it."""

import pytest

from ara.grammars import (
    And,
    Atom,
    Eventually,
    Interval,
    Not,
    Or,
    Until,
    atoms,
    depth,
    max_bound,
    parse,
)
from ara.grammars.ast import ASTError, atoms_read_now, rename_atoms, signed_atoms


@pytest.mark.parametrize(
    ("build", "message"),
    [
        (lambda: Atom("F"), "reserved word"),  # keywords cannot name propositions
        (lambda: Atom("go-to"), r"\[A-Za-z_\]"),  # not an identifier
        (lambda: Atom("1a"), r"\[A-Za-z_\]"),
        (lambda: Interval(-1, 3), "lower bound must be an integer >= 0"),
        (lambda: Interval(5, 2), "upper bound must be an integer >= lower bound 5"),
        (lambda: And((Atom("a"),)), "at least 2"),  # one argument is no conjunction
        (lambda: Or([Atom("a"), Atom("b")]), "tuple"),  # lists are not hashable
    ],
)
def test_bad_nodes_are_refused(build, message):
    """Tests that malformed nodes fail at construction with a clear message."""
    with pytest.raises(ASTError, match=message):
        build()


def test_atoms_depth_and_largest_bound_are_read_from_the_tree():
    """Tests atoms, depth and max_bound on one formula."""
    until = Until(Atom("b"), Atom("a"), Interval(0, 4))
    f = And((Eventually(Atom("a"), Interval(2, 9)), Not(until)))
    assert atoms(f) == {"a", "b"}
    assert depth(f) == 3
    assert max_bound(f) == 9


@pytest.mark.parametrize(("formula", "now"), [
    ("a -> F(b)", {"a"}),
    ("G(a -> b)", set()),
    ("(a & !b) | (c U d)", {"a", "b"}),
    ("F(a) <-> b", {"b"}),
])
def test_atoms_read_now_are_those_outside_every_temporal_operator(formula, now):
    """Tests which propositions a formula reads at its first instant only."""
    from ara.grammars import parse

    assert atoms_read_now(parse(formula)) == now


def test_rename_atoms_keeps_structure_and_intervals():
    """Tests renaming lifted propositions to grounded names."""
    f = Until(Atom("prop_1"), Not(Atom("prop_2")), Interval(1, 3))
    g = rename_atoms(f, {"prop_1": "at_door", "prop_2": "holding_box"})
    assert g == Until(Atom("at_door"), Not(Atom("holding_box")), Interval(1, 3))


def test_the_language_core_needs_no_language_model():
    """`ara.grammars` (AST, parser, printer, grammars, Spot bridge, English) loads
    without llama.cpp, torch or transformers: the LLM parts live in `ara.eval`."""
    import subprocess
    import sys

    code = ("import sys, ara.grammars, ara.grammars.spot_bridge, ara.grammars.english; "
            "print(sorted({'llama_cpp', 'torch', 'transformers'} & set(sys.modules)))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "[]"
    # Nor does any of its modules reach for one lazily.
    from pathlib import Path

    import ara.grammars

    for module in Path(ara.grammars.__file__).parent.glob("*.py"):
        text = module.read_text()
        assert not any(name in text for name in ("llama_cpp", "import torch",
                                                 "transformers")), module.name


def test_signed_atoms_read_an_implication_premise_as_a_negation():
    assert signed_atoms(parse("G(a -> !F(b))")) == {("a", True), ("b", True)}
    assert signed_atoms(parse("!(a -> b) & c")) == {("a", False), ("b", True), ("c", False)}
    assert signed_atoms(parse("a <-> b")) == {(n, s) for n in "ab" for s in (True, False)}
