"""A request analysed once: the numbers, claims, nestings and order its words ask for."""

from ara.eval.translate.request import Request, written_numbers
from ara.grammars.nesting import AGAIN_AND_AGAIN, FOR_GOOD, HOLDS


def test_numbers_that_name_a_proposition_are_not_bounds():
    """Tests that prop_2 written out and the 8 of "pallet 8" (deliver_pallet_8) state no
    time, though the grammar may write them."""
    assert Request.of("( prop_1 ) until ( prop_2 )", ["prop_1", "prop_2"]).stated == set()
    request = Request.of("Bring pallet 8 to the loading dock within 250 steps.",
                         ["deliver_pallet_8"])
    assert request.stated == {250} and request.numbers == {8, 250}


def test_number_words_count_next_to_a_word_of_time():
    """Tests number words as time, and counts that state no bound."""
    assert Request.of("keep ( prop_1 ) between step ten and step 30", ["prop_1"]).stated == {
        10, 30}
    assert Request.of("reach the dock within five more steps", ["reach_dock"]).stated == {5}
    # "one" and "two" that count things state no bound
    assert Request.of("at least one of ( prop_1 ) or ( prop_2 ), not the two together",
                      ["prop_1", "prop_2"]).stated == set()
    # a lifted name the sentence writes but the proposition list lacks is no number either
    assert Request.of("when possible ( prop_1 ) ( prop_2 )", ["prop_2"]).stated == set()


def test_the_grammar_may_write_every_number_the_sentence_writes():
    """Tests the numbers a request's grammar reads, in digits or words."""
    assert written_numbers("within 20 steps reach the door, then wait ten") == {20, 10}
    assert written_numbers("Pick up the pallet at (3, 4)") == {3, 4}
    assert written_numbers("always avoid the door") == set()


def test_what_a_request_is_checked_for_before_translation():
    """Tests the propositions a sentence never names (a word of 3+ letters counts), and
    the numbers in digits, which a bound above the grammar's largest refuses."""
    request = Request.of("Go to the kitchen, wait ten minutes or 1200 steps",
                         ["go_to_kitchen", "open_door"])
    assert request.unmentioned == ("open_door",)
    assert request.digits == {1200} and request.numbers == {10, 1200}


def test_a_then_after_a_condition_and_sooner_or_later_order_nothing():
    """Tests which sentences ask for one step after another."""
    assert not Request.of("If the door is open, then close it.", ()).ordered
    assert not Request.of("Sooner or later, reach the balcony.", ()).ordered
    assert not Request.of("Reach the dock no later than step 80.", ()).ordered
    assert Request.of("Open the valve, and close it at some later point.", ()).ordered
    assert Request.of("charge, then go back to work", ()).ordered
    assert Request.of("Visit a and b, in any order.", ()).any_order


def test_words_that_name_a_proposition_or_say_no_time_ask_for_nothing():
    """Tests that "keep apple" names keep_apple, "stay at the lab" at_lab in the
    realizer's words, "a or b, never both" is an exclusive or, and "within 10 steps"
    may hold or happen."""
    assert Request.of("keep apple and at any time visit the tree",
                      ["keep_apple", "visit_tree"]).claims == ()
    assert Request.of("Stay at the lab, then bring the tool.", ()).claims == ()
    assert Request.of("Wait, stay still, and then leave.", ()).claims == ()
    assert Request.of("(prop_1) or (prop_2), never both.", ()).claims == ()
    assert Request.of("reach (prop_1) within 10 steps", ()).claims == ()
    stay = Request.of("Go to the dock and stay there.", ())
    assert stay.claims == (HOLDS,) and stay.asking_word(HOLDS) == "stay"


def test_the_nestings_a_sentence_allows():
    """Tests that "every so often" allows G(F) and "stay there" F(G), and neither the other."""
    assert Request.of("Inspect the forklift every so often.", ()).allows == {AGAIN_AND_AGAIN}
    assert Request.of("Go to the charging station and stay there.", ()).allows == {FOR_GOOD}


def test_the_propositions_a_condition_clause_names():
    """Tests that a proposition belongs to the condition where most of its words are."""
    def named(nl, aps):
        return Request.of(nl, aps).conditions

    request = Request.of("If security flags a bag, take it to the inspection room.",
                         ["bag_flagged", "bag_at_inspection_room"])
    assert (request.conditions, request.outcomes) == ({"bag_flagged"}, {"bag_at_inspection_room"})
    assert named("Keep the lights on while you are deeper than 50 meters.",
                 ["lights_on", "deeper_than_50m"]) == {"deeper_than_50m"}
    assert named("whenever ( prop_2 ) is true, ( prop_1 ) must be false",
                 ["prop_1", "prop_2"]) == {"prop_2"}
    # "only when" turns it round; "at least once" and "at once" open no condition
    assert not named("Enter the cold room only when the door is open.",
                     ["in_cold_room", "door_open"])
    assert not named("Sound the alarm at least once and stop the pump at once.",
                     ["sound_alarm", "stop_pump"])


def test_a_condition_is_named_plainly_in_all_its_words_and_not_negated():
    """Tests which conditions a clause says in the words of their names: only those can
    tell a condition read as a consequence from a contrapositive."""
    def plain(nl, aps):
        request = Request.of(nl, aps)
        return request.conditions, request.plain_conditions

    assert plain("Stop whenever the guard is open.", ["stop", "guard_open"]) == (
        {"guard_open"}, {"guard_open"})
    assert plain("Stop whenever the guard is off.", ["stop", "guard_on"]) == ({"guard_on"}, set())
    assert plain("Stop whenever no guard is present.", ["stop", "guard_present"]) == (
        {"guard_present"}, set())
