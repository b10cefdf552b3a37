"""What an answer leaves out of its request, and adds unasked: the signals repair acts on."""

from dataclasses import fields

from ara.data.synthetic import synthetic_records
from ara.eval.translate.checks import (
    CHECKS,
    KINDS,
    Gaps,
    gaps,
    mends,
    reversed_conditions,
    unasked,
    unclaimed,
)
from ara.eval.translate.request import Request
from ara.grammars import Implies, Not, parse, to_text, walk
from ara.grammars.nesting import AGAIN_AND_AGAIN, FOR_GOOD, HAPPENS, HOLDS, RESTATED, nested_pairs


def _gaps(nl, aps, stl):
    return gaps(Request.of(nl, aps), parse(stl))


def test_a_dropped_bound_and_a_dropped_proposition_are_gaps():
    """Tests that a listed proposition and a stated bound no answer writes are gaps."""
    nl = "At some point go to the kitchen, never go to the garage, and charge within 20 steps."
    aps = ["go_to_kitchen", "go_to_garage", "charge"]
    # "never" asks for something to hold over time, which neither F says
    assert _gaps(nl, aps, "F(go_to_kitchen) & F(charge)") == Gaps(
        aps=("go_to_garage",), numbers=(20,), claims=("G",))
    assert not _gaps(nl, aps, "F(go_to_kitchen) & G(!go_to_garage) & F[0,20](charge)")


def test_numbers_that_name_a_proposition_and_both_ends_of_an_interval_count():
    """Tests that the 8 of "pallet 8" is no bound and either end of an interval writes one."""
    nl = "Bring pallet 8 to the loading dock within 250 steps."
    assert _gaps(nl, ["deliver_pallet_8"], "F[0,250](deliver_pallet_8)") == Gaps()
    nl = "keep ( prop_1 ) between step ten and step 30"
    assert _gaps(nl, ["prop_1"], "G[10,30](prop_1)") == Gaps()
    assert _gaps(nl, ["prop_1"], "G[0,30](prop_1)").numbers == (10,)


def test_an_untimed_request_with_every_proposition_has_no_gap():
    """Tests that a gap counts one per thing left out."""
    nl = "( prop_1 ) or ( prop_2 ) at some point"
    assert len(_gaps(nl, ["prop_1", "prop_2"], "F(prop_1 | prop_2)")) == 0
    assert len(_gaps(nl, ["prop_1", "prop_2"], "F(prop_1)")) == 1


def test_nesting_the_sentence_never_asks_for_is_a_gap():
    """Tests that "always keep a firm grip" asks for no grip again and again, and
    "reach the garden" for no staying there."""
    grip = _gaps("Always keep a firm grip on the bottle.", ["grip_bottle"], "G(F(grip_bottle))")
    assert grip == Gaps(unasked=("G(F(grip_bottle))",))
    assert "G(F(grip_bottle)) (again and again)" in grip.warning()
    answer = parse("G(!at_stairs) & F(G(at_garden))")
    keep = Request.of("Keep away from the stairs and eventually reach the garden.", ())
    assert unasked(keep, answer) == ()  # "keep": for good
    avoid = Request.of("Avoid the stairs and reach the garden.", ())
    assert [to_text(f) for f in unasked(avoid, answer)] == ["F(G(at_garden))"]


def test_words_for_a_pair_license_it_and_a_restated_operator_never_is():
    """Tests that "every so often" and "stay there" license their pairs; F in F never."""
    assert not _gaps("Inspect the forklift every so often.", ["inspect_forklift"],
                     "G(F(inspect_forklift))")
    assert not _gaps("Go to the charging station and stay there.", ["at_charging_station"],
                     "F(G(at_charging_station))")
    nl = "between time 10 and time 25, (prop_1) must happen at least once"
    assert _gaps(nl, ["prop_1"], "F[10,25](F(prop_1))").unasked == ("F[10,25](F(prop_1))",)
    assert not _gaps(nl, ["prop_1"], "F[10,25](prop_1)")


def test_a_window_over_an_unbounded_f_is_asked_for_only_with_words_that_it_happens():
    """Tests that "keep the oven on for 45 minutes" asks for no ``G[0,45](F(...))``, and
    that dropping its ``F`` mends it, while NL2TL's wording of that formula asks for it."""
    keep = Request.of("Keep the oven on for 45 minutes.", ["oven_on"])
    answer = parse("G[0,45](F(oven_on))")
    assert [to_text(f) for f in unasked(keep, answer)] == ["G[0,45](F(oven_on))"]
    assert "G[0,45](oven_on)" in map(to_text, mends(keep, answer))
    nl2tl = ("for every moment within the next 0 to 5 time units, there must be sometime "
             "in the future that (prop_1)")
    assert not _gaps(nl2tl, ["prop_1"], "G[0,5](F(prop_1))")


def test_plain_words_for_staying_and_recurring_license_their_pairs():
    """Tests that "leave it there" and "never ... again" allow for good, "time after
    time" again and again."""
    assert not _gaps("Park the cart in bay 2 and leave it there.", ["cart_in_bay_2"],
                     "F(G(cart_in_bay_2))")
    assert not _gaps("Lock the hatch and never open it again.", ["hatch_open"],
                     "F(G(!hatch_open))")
    assert not _gaps("Check the pump, time after time.", ["check_pump"], "G(F(check_pump))")
    assert _gaps("Check the pump, time after time.", ["check_pump"], "G(check_pump)").claims
    # neither across a clause nor negated
    for nl in ("Never enter the lab and visit the dock again and again.",
               "Do not leave it there: park the cart in bay 2."):
        assert FOR_GOOD not in Request.of(nl, ()).allows, nl


def test_generated_sentences_never_ask_for_less_than_their_formula_says():
    """Tests that no realized sentence reads as not asking for its formula's nesting or
    order: repair must not undo what the model learned from them."""
    for record in synthetic_records(300, seed=3, held_out=False):
        formula, request = parse(record.stl), Request.of(record.nl, record.aps)
        kinds = {next(nested_pairs(node), (None, "order"))[1]
                 for node in unasked(request, formula)}
        assert kinds <= {RESTATED}, (record.nl, record.stl)  # random draws restate
        assert not gaps(request, formula).order, (record.nl, record.stl)


def test_an_order_asked_for_and_one_never_asked_for_are_gaps():
    """Tests both ways of getting order wrong."""
    nl = "Go to the mailroom, then the gym."
    aps = ["go_to_mailroom", "go_to_gym"]
    assert _gaps(nl, aps, "F(go_to_mailroom) & F(go_to_gym)") == Gaps(order=True)
    assert not _gaps(nl, aps, "F(go_to_mailroom & F(go_to_gym))")
    assert "orders nothing in time" in Gaps(order=True).warning()
    nl = "Visit the mailroom and the gym, in any order."
    assert _gaps(nl, aps, "F(go_to_mailroom & F(go_to_gym))").unasked == (
        "F(go_to_mailroom & F(go_to_gym))",)
    assert not _gaps(nl, aps, "F(go_to_mailroom) & F(go_to_gym)")


def test_what_the_sentence_asks_to_hold_happen_or_recur_and_the_answer_never_says():
    """Tests claims left out, and the warning quoting the words that ask for them."""
    nl = "Between step 10 and step 20, keep the door locked."
    assert _gaps(nl, ["door_locked"], "F[10,20](door_locked)") == Gaps(claims=(HOLDS,))
    assert not _gaps(nl, ["door_locked"], "G[10,20](door_locked)")
    nl = "Do not enter the loading bay during the first 20 seconds, but enter it at some point."
    request = Request.of(nl, ["enter_loading_bay"])
    assert unclaimed(request, parse("G[0,20](!enter_loading_bay)")) == (HAPPENS,)
    nl = "Inspect the forklift every so often."
    request = Request.of(nl, ["inspect_forklift"])
    assert unclaimed(request, parse("G(inspect_forklift)")) == (AGAIN_AND_AGAIN,)
    slip = gaps(request, parse("G(inspect_forklift)"))
    assert "never says that anything happens again and again (G(F)), as the sentence asks" in (
        slip.warning())
    assert ('never says that anything happens again and again (G(F)), which "every so often" '
            "asks for") in slip.warning(request)
    # "never" is read through negations: !F(a) says G(!a)
    assert not unclaimed(Request.of("Never enter the lab.", ["enter_lab"]), parse("!F(enter_lab)"))


def test_generated_sentences_never_ask_for_a_claim_their_formula_lacks():
    """Tests that repair cannot undo what the model learned from the realizer's sentences."""
    for record in synthetic_records(600, seed=5, held_out=False):
        assert not unclaimed(Request.of(record.nl, record.aps), parse(record.stl)), (
            record.nl, record.stl)


def test_a_condition_read_as_the_consequence_is_a_gap():
    """Tests that what a "whenever", "if" or "while" clause names belongs before the arrow,
    that trading it with the premise mends the answer, and that a contrapositive passes."""
    nl = "Sound the alarm within 10 seconds whenever a ward door is left open."
    request = Request.of(nl, ["sound_alarm", "ward_door_open"])
    slip = parse("G(sound_alarm -> F[0,10](ward_door_open))")
    assert gaps(request, slip) == Gaps(condition=("sound_alarm -> F[0,10](ward_door_open)",))
    assert "puts what the sentence names as the condition after the arrow" in (
        gaps(request, slip).warning())
    assert mends(request, slip) == [parse("G(ward_door_open -> F[0,10](sound_alarm))")]
    assert not _gaps(nl, request.aps, "G(ward_door_open -> F[0,10](sound_alarm))")
    # the negation goes with its proposition: not G(!guard_off -> running), which says the same
    nl, aps = "Never run the crusher while its guard is off.", ["crusher_running", "guard_off"]
    assert "G(guard_off -> !crusher_running)" in map(
        to_text, mends(Request.of(nl, aps), parse("G(!crusher_running -> guard_off)")))
    assert not _gaps(nl, aps, "G(crusher_running -> !guard_off)")  # the contrapositive
    assert not _gaps(nl, aps, "G(!(crusher_running & guard_off))")  # no arrow to misread


def test_sentences_that_leave_the_condition_open_name_none():
    """Tests that "only when" turns the condition round and NL2TL's "a means that b"
    puts it first, so the check reads nothing there."""
    nl = "The forklift may only be in the cold room when the door is open."
    assert not _gaps(nl, ["door_open", "in_cold_room"], "G(in_cold_room -> door_open)")
    assert not _gaps("( prop_1 ) means that whenever ( prop_2 )", ["prop_1", "prop_2"],
                     "prop_1 -> F(prop_2)")


def test_a_contrapositive_is_no_condition_turned_round():
    """Tests that a state the clause names in other words, or negates, can sit after the
    arrow: the answer may be the contrapositive of the one with it before."""
    for nl, aps, right in [
        ("Never run the crusher while its guard is off.", ["crusher_running", "guard_on"],
         "G(crusher_running -> guard_on)"),
        ("Do not enter the cold room when the door is closed.", ["in_cold_room", "door_open"],
         "G(in_cold_room -> door_open)"),
        ("Never leave the drawer open when no cashier is at the register.",
         ["drawer_open", "cashier_at_register"], "G(drawer_open -> cashier_at_register)"),
    ]:
        assert not _gaps(nl, aps, right), nl
    # a reaction has no contrapositive a sentence says, and <-> no direction
    nl, aps = "Whenever the bell rings, go to the door.", ["bell_rings", "at_door", "lit"]
    assert _gaps(nl, aps, "G(at_door -> F(bell_rings))").condition
    assert not _gaps(nl, aps, "G(at_door -> (bell_rings <-> lit))")


def test_generated_sentences_never_read_as_a_condition_turned_round():
    """Tests that repair cannot undo the realizer's conditions, nor flag the
    contrapositive of one (``!b -> !a`` for ``a -> b``), which says the same."""
    for record in synthetic_records(1000, seed=7, held_out=False):
        request, formula = Request.of(record.nl, record.aps), parse(record.stl)
        assert not gaps(request, formula).condition, (record.nl, record.stl)
        for arrow in (node for node in walk(formula) if isinstance(node, Implies)):
            turned = Implies(Not(arrow.rhs), Not(arrow.lhs))
            assert not reversed_conditions(request, turned), (record.nl, to_text(turned))


def test_mends_close_the_gap_of_their_kind():
    """Tests that each kind's mends write what was left out or drop what was added."""
    request = Request.of("Charge, then reach the dock within 9 steps.", ("charge", "at_dock"))
    assert {"F(charge & F(at_dock))",  # order: the steps chained
            "F(charge) & F[0,9](at_dock)"} <= {  # numbers: the bound written
        to_text(f) for f in mends(request, parse("F(charge) & F(at_dock)"))}
    restated = parse("F(charge & F(F(at_dock)))")
    assert "F(charge & F(at_dock))" in map(to_text, mends(request, restated))  # unasked
    assert not any("9" in to_text(f) for f in mends(request, restated, timed=False))


def test_each_kind_is_one_check_and_one_field_of_gaps():
    """Tests that the registry and the record of gaps name the same kinds, in order."""
    assert KINDS == ("aps", "numbers", "unasked", "order", "claims", "condition")
    assert KINDS == tuple(check.kind for check in CHECKS) == tuple(f.name for f in fields(Gaps))


def test_kinds_of_a_gap_in_a_fixed_order_and_its_json_round_trip():
    """Tests the --json shape of a gap and that it reads back."""
    gap = Gaps(aps=("a",), unasked=("G(F(b))",), order=True, claims=("G",))
    assert gap.kinds() == ["aps", "unasked", "order", "claims"]
    assert gap.to_json() == {"left_out": {"aps": ["a"], "numbers": [], "order": True,
                                          "claims": ["G"]}, "unasked": ["G(F(b))"],
                             "condition": []}
    assert list(gap.to_json()) == ["left_out", "unasked", "condition"]
    assert Gaps.from_json(gap.to_json()) == gap
    assert not Gaps.from_json({"stl": None})  # an answer that did not parse has no fields
    assert gap.count(timed=False) == len(gap) == 4
