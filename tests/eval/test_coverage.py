"""What an answer leaves out of its request, and adds unasked: the signals repair acts on."""

from ara.data.synthetic import synthetic_records
from ara.eval.coverage import (
    AGAIN_AND_AGAIN_WORDS,
    FOR_GOOD_WORDS,
    Gaps,
    asked_claims,
    asks_for_order,
    gaps,
    stated_numbers,
    unasked,
    unclaimed,
)
from ara.grammars import parse, to_text
from ara.grammars.english import PHRASES
from ara.grammars.nesting import AGAIN_AND_AGAIN, HAPPENS, HOLDS, RESTATED, nested_pairs


def test_a_dropped_bound_and_a_dropped_proposition_are_gaps():
    nl = "At some point go to the kitchen, never go to the garage, and charge within 20 steps."
    aps = ["go_to_kitchen", "go_to_garage", "charge"]
    # "never" asks for something to hold over time, which neither F says
    assert gaps(nl, aps, parse("F(go_to_kitchen) & F(charge)")) == Gaps(
        aps=("go_to_garage",), numbers=(20,), claims=("G",))
    assert not gaps(nl, aps, parse("F(go_to_kitchen) & G(!go_to_garage) & F[0,20](charge)"))


def test_numbers_that_name_a_proposition_are_not_bounds():
    # prop_2 written out, and the 8 of "pallet 8" (deliver_pallet_8), say no time bound
    assert stated_numbers("( prop_1 ) until ( prop_2 )", ["prop_1", "prop_2"]) == set()
    nl = "Bring pallet 8 to the loading dock within 250 steps."
    assert stated_numbers(nl, ["deliver_pallet_8"]) == {250}
    assert gaps(nl, ["deliver_pallet_8"], parse("F[0,250](deliver_pallet_8)")) == Gaps()


def test_number_words_count_next_to_a_word_of_time_and_both_ends_of_an_interval_count():
    nl = "keep ( prop_1 ) between step ten and step 30"
    assert stated_numbers(nl, ["prop_1"]) == {10, 30}
    assert stated_numbers("reach the dock within five more steps", ["reach_dock"]) == {5}
    # "one" and "two" that count things state no bound
    assert stated_numbers("at least one of ( prop_1 ) or ( prop_2 ), not the two together",
                          ["prop_1", "prop_2"]) == set()
    # a lifted name the sentence writes but the proposition list lacks is no number either
    assert stated_numbers("when possible ( prop_1 ) ( prop_2 )", ["prop_2"]) == set()
    assert gaps(nl, ["prop_1"], parse("G[10,30](prop_1)")) == Gaps()
    assert gaps(nl, ["prop_1"], parse("G[0,30](prop_1)")).numbers == (10,)


def test_an_untimed_request_with_every_proposition_has_no_gap():
    nl = "( prop_1 ) or ( prop_2 ) at some point"
    assert len(gaps(nl, ["prop_1", "prop_2"], parse("F(prop_1 | prop_2)"))) == 0
    assert len(gaps(nl, ["prop_1", "prop_2"], parse("F(prop_1)"))) == 1


def test_nesting_the_sentence_never_asks_for_is_a_gap():
    """"Always keep a firm grip" asks for no grip again and again; "reach the garden"
    for no staying there."""
    grip = gaps("Always keep a firm grip on the bottle.", ["grip_bottle"],
                parse("G(F(grip_bottle))"))
    assert grip == Gaps(unasked=("G(F(grip_bottle))",))
    assert "G(F(grip_bottle)) (again and again)" in grip.warning()
    nl = "Keep away from the stairs and eventually reach the garden."
    assert unasked(nl, parse("G(!at_stairs) & F(G(at_garden))")) == ()  # "keep": for good
    nl = "Avoid the stairs and reach the garden."
    assert [to_text(f) for f in unasked(nl, parse("G(!at_stairs) & F(G(at_garden))"))] == [
        "F(G(at_garden))"]


def test_words_for_a_pair_license_it_and_a_restated_operator_never_is():
    assert not gaps("Inspect the forklift every so often.", ["inspect_forklift"],
                    parse("G(F(inspect_forklift))"))
    assert not gaps("Go to the charging station and stay there.", ["at_charging_station"],
                    parse("F(G(at_charging_station))"))
    nl = "between time 10 and time 25, (prop_1) must happen at least once"
    assert gaps(nl, ["prop_1"], parse("F[10,25](F(prop_1))")).unasked == ("F[10,25](F(prop_1))",)
    assert not gaps(nl, ["prop_1"], parse("F[10,25](prop_1)"))


def test_the_realizer_phrasings_for_each_pair_have_the_words_for_it():
    """Training sentences say these pairs in the realizer's words: none of them may
    read as unasked, or repair would undo what the model learned."""
    for key, words in (("GF", AGAIN_AND_AGAIN_WORDS), ("GF_place", AGAIN_AND_AGAIN_WORDS),
                       ("GF2_place", AGAIN_AND_AGAIN_WORDS), ("FG", FOR_GOOD_WORDS),
                       ("FG_place", FOR_GOOD_WORDS), ("F_then_G", FOR_GOOD_WORDS)):
        for phrase in PHRASES[key]:
            assert words.search(phrase.lower()), (key, phrase)


def test_generated_sentences_never_ask_for_less_than_their_formula_says():
    """Nor for an order their formula does not write: repair must not undo what the
    model learned from them."""
    for record in synthetic_records(300, seed=3, held_out=False):
        formula = parse(record.stl)
        kinds = {next(nested_pairs(node), (None, "order"))[1]
                 for node in unasked(record.nl, formula)}
        assert kinds <= {RESTATED}, (record.nl, record.stl)  # random draws restate
        assert not gaps(record.nl, record.aps, formula).unordered, (record.nl, record.stl)


def test_an_order_asked_for_and_one_never_asked_for_are_gaps():
    nl = "Go to the mailroom, then the gym."
    aps = ["go_to_mailroom", "go_to_gym"]
    assert gaps(nl, aps, parse("F(go_to_mailroom) & F(go_to_gym)")) == Gaps(unordered=True)
    assert not gaps(nl, aps, parse("F(go_to_mailroom & F(go_to_gym))"))
    assert "orders nothing in time" in Gaps(unordered=True).warning()
    nl = "Visit the mailroom and the gym, in any order."
    assert gaps(nl, aps, parse("F(go_to_mailroom & F(go_to_gym))")).unasked == (
        "F(go_to_mailroom & F(go_to_gym))",)
    assert not gaps(nl, aps, parse("F(go_to_mailroom) & F(go_to_gym)"))


def test_a_then_after_a_condition_and_sooner_or_later_order_nothing():
    assert not asks_for_order("If the door is open, then close it.")
    assert not asks_for_order("Sooner or later, reach the balcony.")
    assert not asks_for_order("Reach the dock no later than step 80.")
    assert asks_for_order("Open the valve, and close it at some later point.")
    assert asks_for_order("charge, then go back to work")


def test_what_the_sentence_asks_to_hold_happen_or_recur_and_the_answer_never_says():
    nl = "Between step 10 and step 20, keep the door locked."
    assert gaps(nl, ["door_locked"], parse("F[10,20](door_locked)")) == Gaps(claims=(HOLDS,))
    assert not gaps(nl, ["door_locked"], parse("G[10,20](door_locked)"))
    nl = "Do not enter the loading bay during the first 20 seconds, but enter it at some point."
    assert unclaimed(nl, ["enter_loading_bay"], parse("G[0,20](!enter_loading_bay)")) == (
        HAPPENS,)
    nl = "Inspect the forklift every so often."
    assert unclaimed(nl, ["inspect_forklift"], parse("G(inspect_forklift)")) == (
        AGAIN_AND_AGAIN,)
    slip = gaps(nl, ["inspect_forklift"], parse("G(inspect_forklift)"))
    assert "never says that anything happens again and again (G(F)), as the sentence asks" in (
        slip.warning())
    assert ('never says that anything happens again and again (G(F)), which "every so often" '
            "asks for") in slip.warning(nl)
    # "never" is read through negations: !F(a) says G(!a)
    assert not unclaimed("Never enter the lab.", ["enter_lab"], parse("!F(enter_lab)"))


def test_words_that_name_a_proposition_or_say_no_time_ask_for_nothing():
    # "keep apple" names keep_apple; "stay at the lab" names at_lab in the realizer's words;
    # "a or b, never both" is an exclusive or; "within 10 steps" may hold or happen
    assert asked_claims("keep apple and at any time visit the tree",
                        ["keep_apple", "visit_tree"]) == set()
    assert asked_claims("Stay at the lab, then bring the tool.") == set()
    assert asked_claims("Wait, stay still, and then leave.") == set()
    assert asked_claims("(prop_1) or (prop_2), never both.") == set()
    assert asked_claims("reach (prop_1) within 10 steps") == set()
    assert asked_claims("Go to the dock and stay there.") == {HOLDS}


def test_generated_sentences_never_ask_for_a_claim_their_formula_lacks():
    """Repair must not undo what the model learned from the realizer's sentences."""
    for record in synthetic_records(600, seed=5, held_out=False):
        assert not unclaimed(record.nl, record.aps, parse(record.stl)), (record.nl, record.stl)


def test_kinds_of_a_gap_in_a_fixed_order_and_its_json_round_trip():
    gap = Gaps(aps=("a",), unasked=("G(F(b))",), unordered=True, claims=("G",))
    assert gap.kinds() == ["aps", "unasked", "order", "claims"]
    assert gap.to_json() == {"left_out": {"aps": ["a"], "numbers": [], "order": True,
                                          "claims": ["G"]}, "unasked": ["G(F(b))"]}
    assert Gaps.from_json(gap.to_json()) == gap
    assert not Gaps.from_json({"stl": None})  # an answer that did not parse has no fields
