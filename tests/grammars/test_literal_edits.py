"""Formulas one edit from a translation that write what it left out."""

from hypothesis import given, settings
from hypothesis import strategies as st

from ara.grammars import atoms, parse, to_text, walk
from ara.grammars.ast import Implies, interval_of
from ara.grammars.literal_edits import claim_edits, condition_trades, literal_edits
from ara.grammars.nesting import AGAIN_AND_AGAIN, HAPPENS, HOLDS, temporal_claims

from conftest import formulas


def texts(stl: str, aps=(), bounds=()) -> set[str]:
    return {to_text(f) for f in literal_edits(parse(stl), aps, bounds)}


def test_a_proposition_in_the_wrong_slot_is_one_edit_away():
    """'Every time the bin is full, empty it within 12 steps', read with the wrong
    trigger: putting bin_full in either slot is among the edits."""
    edits = texts("G(empty_bin -> F[0,12](empty_bin))", aps=["bin_full"])
    assert {"G(bin_full -> F[0,12](empty_bin))", "G(empty_bin -> F[0,12](bin_full))"} <= edits


def test_a_left_out_constraint_comes_back_as_a_conjunct_or_a_trigger():
    edits = texts("F(go_to_kitchen) & F(go_to_office)", aps=["go_to_garage"])
    assert "(F(go_to_kitchen) & F(go_to_office)) & G(!go_to_garage)" in edits
    assert "F(go_to_kitchen) & F(go_to_office | go_to_garage)" in edits
    assert "go_to_garage -> (F(go_to_kitchen) & F(go_to_office))" in edits


def test_a_stated_bound_goes_onto_each_temporal_operator():
    """'Unload the truck, and within 10 steps after that, sweep the floor.'"""
    edits = texts("F(unload_truck & F(sweep_floor))", bounds=[10])
    assert {"F(unload_truck & F[0,10](sweep_floor))",
            "F[0,10](unload_truck & F(sweep_floor))"} <= edits
    assert all("unload_truck" in e and "sweep_floor" in e for e in edits)  # nothing dropped


def test_a_bound_replaces_one_end_of_an_interval_and_two_bounds_make_one():
    assert texts("F[0,400](a) & F[0,400](b)", bounds=[250]) >= {
        "F[0,250](a) & F[0,400](b)", "F[0,400](a) & F[0,250](b)"}
    assert texts("F[5,20](a)", bounds=[8]) >= {"F[5,8](a)", "F[8,20](a)", "F[0,8](a)"}
    assert "G[3,19](a)" in texts("G(a)", bounds=[3, 19])


def test_nothing_left_out_means_no_edit():
    assert literal_edits(parse("F(a) & G(b)")) == []


@settings(max_examples=60, deadline=None)
@given(formulas(aps=("a", "b"), timed=True, max_bound=20),
       st.lists(st.sampled_from(["c", "d"]), max_size=2, unique=True),
       st.lists(st.integers(21, 40), max_size=2, unique=True))
def test_every_edit_writes_something_that_was_left_out(formula, aps, bounds):
    """The edits are there to close a gap, so each one must write a new literal, and
    the original formula is never among them."""
    original = to_text(formula)
    for edit in literal_edits(formula, aps, bounds):
        written = {n for node in walk(edit) if (iv := interval_of(node)) is not None
                   for n in (iv.lo, iv.hi)}
        assert atoms(edit) & set(aps) or written & set(bounds), to_text(edit)
        assert to_text(edit) != original


def test_a_claim_the_sentence_asks_for_is_one_edit_away():
    def edits(stl: str, claim: str) -> set[str]:
        return {to_text(f) for f in claim_edits(parse(stl), [claim])}

    # "between step 10 and step 20, keep the door locked"
    assert "G[10,20](door_locked)" in edits("F[10,20](door_locked)", HOLDS)
    # "go to the charging station and stay there"
    assert "F(drop & F(G(at_station)))" in edits("F(drop & F(at_station))", HOLDS)
    # "(a) should happen, and (b) should hold until then"
    assert "b U a" in edits("a & b", HOLDS)
    # "never during the first 20 seconds, but at some point"
    assert "G[0,20](!enter_bay) & F(enter_bay)" in edits("G[0,20](!enter_bay)", HAPPENS)
    # "inspect the forklift every so often", "at least once in every 10-step window"
    assert "G(F(inspect_forklift))" in edits("G(inspect_forklift)", AGAIN_AND_AGAIN)
    assert "G(F[0,10](a))" in edits("G[0,10](a)", AGAIN_AND_AGAIN)


@settings(max_examples=60, deadline=None)
@given(formulas(aps=("a", "b"), timed=True, max_bound=20),
       st.sampled_from([HOLDS, HAPPENS, AGAIN_AND_AGAIN]))
def test_every_claim_edit_makes_the_claim_it_was_asked_for(formula, claim):
    original = to_text(formula)
    for edit in claim_edits(formula, [claim]):
        assert claim in temporal_claims(edit), (original, to_text(edit))
        assert to_text(edit) != original


def test_a_condition_and_a_premise_trade_places_with_their_signs():
    def trades(stl: str, names: set[str]) -> list[str]:
        formula = parse(stl)
        arrows = [node for node in walk(formula) if isinstance(node, Implies)]
        return [to_text(f) for f in condition_trades(formula, arrows, frozenset(names))]

    # "whenever the trough runs low, refill it within 10 minutes"
    assert trades("G(refill -> F[0,10](trough_low))", {"trough_low"}) == [
        "G(trough_low -> F[0,10](refill))"]
    assert trades("G(!running -> guard_off)", {"guard_off"}) == ["G(guard_off -> !running)"]
    # every occurrence is put for the other, double negations dropped
    assert trades("G(!p -> (c & F(!c)))", {"c"}) == ["G(c -> (!p & F(p)))"]
    assert trades("G(a -> b)", {"c"}) == []
