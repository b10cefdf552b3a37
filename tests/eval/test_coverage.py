"""What an answer leaves out of its request: the signal repair acts on."""

from ara.eval.coverage import Gaps, gaps, stated_numbers
from ara.grammars import parse


def test_a_dropped_bound_and_a_dropped_proposition_are_gaps():
    nl = "At some point go to the kitchen, never go to the garage, and charge within 20 steps."
    aps = ["go_to_kitchen", "go_to_garage", "charge"]
    assert gaps(nl, aps, parse("F(go_to_kitchen) & F(charge)")) == Gaps(
        aps=("go_to_garage",), numbers=(20,))
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
