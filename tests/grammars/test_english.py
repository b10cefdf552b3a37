"""The English realizer: deterministic readings, varied wordings, held-out phrasings."""

from __future__ import annotations

import random
import re

import pytest
from hypothesis import given, settings

from ara.errors import ConfigError
from ara.grammars import parse
from ara.grammars.english import HELD_OUT, PHRASES, Realizer, explain, realize

from conftest import formulas


@pytest.mark.parametrize(
    ("formula", "english"),
    [
        ("G(!a)", "never a"),  # avoidance is an idiom, not "always not a"
        ("G(F(a))", "a infinitely often"),
        ("F(G(a))", "eventually a forever"),
        ("F(a & F(b))", "first a, then b"),
        ("F(a & F(b & F(c)))", "first a, then b, then c"),
        # a deadline counted from the step before, and a last step for good
        ("F(a & F[0,10](b))", "a, and within 10 steps after that, b"),
        ("F(a & F(G(b)))", "first a, then eventually b forever"),
        ("G(a -> F[0,5](b))", "whenever a, b within 5 steps"),
        ("G[0,7](!a)", "never a in the first 7 steps"),
        ("F[3,9](a)", "at some point between step 3 and step 9, a"),
        ("!a U b", "do not a until b"),
        ("a U[0,4] b", "a until b, which must happen within 4 steps"),
        ("F(a & b)", "eventually both a and b"),  # the scope of F shows in "both"
        ("F(a) & b", "eventually a, and b"),
        ("(a | b) -> F(c)", "if either a or b, then eventually c"),
        ("F(pick & F(place)) & G(!obstacle)", "first pick, then place, and never obstacle"),
        ("F(a & G(b))", "eventually a, and from then on always b"),
        ("(a | b) & !(a & b)", "a or b, but not both"),
        # a recurrence with a longest gap, and what holds unless a condition does
        ("G(F[0,6](a))", "a at least once every 6 steps"),
        ("G(!a -> b)", "b unless a"),
        ("G(!a -> F(b))", "whenever not a, eventually b"),  # a response, not "unless"
        ("(F(a) | F(b)) & !(F(a) & F(b))", "eventually a or eventually b, but not both"),
        # a state reached and kept a while
        ("F(a & G[0,15](a))", "eventually a, and it stays so for 15 steps"),
        # a precedence: b required, never before a
        ("(!b U a) & F(b)", "b, but only after a"),
        # a bounded F over an until: commas keep "for good" off b
        ("F[0,31](G(a U b))", "no later than step 31, a until b, and it stays so from then on"),
    ],
)
def test_explain_reads_idioms_and_scope(formula, english):
    """Tests the deterministic reading of common patterns and of operator scope."""
    assert explain(parse(formula)) == english


@settings(max_examples=300, deadline=None)
@given(formulas(timed=True, max_bound=50))
def test_every_formula_has_a_reading_that_names_all_its_propositions(f):
    """Tests that explain never fails and names each proposition of the formula, as a
    word of its own ("a" inside "eventually" does not count)."""
    text = explain(f)
    assert text
    for name in ("a", "b", "c"):
        if any(getattr(n, "name", None) == name for n in _nodes(f)):
            assert re.search(rf"\b{name}\b", text), (name, text)


def _nodes(f):
    from ara.grammars.ast import walk

    return list(walk(f))


def test_realize_is_seeded_and_varied():
    """Tests that one seed gives one sentence and different seeds give different ones."""
    f = parse("G(door -> F[0,10](close)) & F(exit)")

    def say(seed: int) -> str:
        return realize(f, Realizer(rng=random.Random(seed), mode="train"))

    assert say(1) == say(1)
    assert len({say(seed) for seed in range(30)}) >= 10


def test_train_mode_never_uses_a_held_out_phrasing():
    """Tests that training wordings avoid every held-out phrasing, and test wordings
    use them."""
    f = parse("G(F(a)) & (G(b -> F(c)) | F(d & F(e)))")
    used_train, used_test = [], []
    for seed in range(200):
        realize(f, Realizer(rng=random.Random(seed), mode="train"), used_train)
        realize(f, Realizer(rng=random.Random(seed), mode="test"), used_test)
    held = {f"{c}:{PHRASES[c].index(p)}" for c, ps in HELD_OUT.items() for p in ps}
    assert not held & set(used_train)
    assert held & set(used_test)


def test_a_command_said_on_its_own_means_at_some_point():
    """Tests that F(action) at the first instant reads as the bare command or another
    "at some point" wording, and that under another operator it never reads bare."""
    said = {"go": "go to the kitchen", "door": "the door is open"}
    realizer = Realizer(rng=random.Random(0), mode="train", say_atom=said.__getitem__,
                        is_action=lambda name: name == "go")
    top = {realize(parse("door -> F(go)"), realizer) for _ in range(200)}
    commands = {p.format(a="go to the kitchen") for p in PHRASES["F_do"]}
    assert any(s.rstrip(".").endswith("then go to the kitchen") for s in top)
    assert all(any(c in s.lower() for c in commands) for s in top)
    nested = {realize(parse("G(F(go))"), realizer).rstrip(".").lower() for _ in range(100)}
    assert "go to the kitchen" not in nested


def test_sampled_wordings_say_visits_in_any_order_and_responses_as_commands():
    """Tests two idioms of sampled sentences (explain keeps the compositional
    reading): F(a) & F(b) as "a and b, in any order", and G(c -> F(a)) with ``a`` a
    command as "whenever c, a", the way a user asks for a later reaction."""
    said = {"go": "go to the kitchen", "pick": "pick up the cup", "low": "the battery is low"}
    realizer = Realizer(rng=random.Random(0), mode="train", say_atom=said.__getitem__,
                        is_action=lambda name: name != "low")
    visits = {realize(parse("F(go) & F(pick)"), realizer).rstrip(".") for _ in range(100)}
    assert "go to the kitchen and pick up the cup, in any order" in {s.lower() for s in visits}
    assert explain(parse("F(a) & F(b)")) == "eventually a, and eventually b"
    assert "in any order" not in explain(parse("G(F(a) & F(b))"))
    responses = {realize(parse("G(low -> F(go))"), realizer).rstrip(".").lower()
                 for _ in range(100)}
    assert "whenever the battery is low, go to the kitchen" in responses
    # (the generator keeps commands out of G(c -> a), which this wording would also fit)
    # A lasting action said bare after "whenever" asks for it then: never for F
    lasting = Realizer(rng=random.Random(0), mode="train", say_atom=said.__getitem__,
                       is_action=lambda name: name != "low",
                       is_lasting=lambda name: name == "go")
    assert not {realize(parse("G(low -> F(go))"), lasting).rstrip(".").lower()
                for _ in range(100)} & {"whenever the battery is low, go to the kitchen"}


def test_realizer_settings_are_checked():
    """Tests that a bad mode or unit is refused where the realizer is built."""
    with pytest.raises(ConfigError, match="mode must be one of"):
        Realizer(mode="dev")
    with pytest.raises(ConfigError, match="unit must index"):
        Realizer(unit=9)


def test_a_plain_or_scopes_inside_and_a_comma_sets_the_outer_one_off():
    """Tests that "always a or b" is taught as G(a | b), the way people say it, and
    never as G(a) | b, which is said with a comma or not begun by its left side."""

    def sayings(formula: str) -> set[str]:
        f = parse(formula)
        return {realize(f, Realizer(rng=random.Random(seed), mode="train")).rstrip(".").lower()
                for seed in range(300)}

    inside = sayings("G(a | b)")
    assert {"always a or b", "a or b at all times"} & inside
    outside = sayings("G(a) | b")
    assert not [s for s in outside if s.endswith(" or b") and ", or" not in s]
    # The plain form is only for propositions: "always a or b and c" would be ambiguous
    assert not [s for s in sayings("G(a | (b & c))") if "or b and c" in s]
    assert explain(parse("G(a) <-> b")) == "always a, if and only if b"


def test_a_place_left_alone_has_its_own_words():
    """Tests that !in_kitchen may be said "stay out of the kitchen", under G as under
    an implication, and that explain, which has no such words, keeps "never"."""
    said = {"in_kitchen": "you are in the kitchen", "wet": "the floor is wet"}
    realizer = Realizer(rng=random.Random(0), mode="train", say_atom=said.__getitem__,
                        say_negated={"in_kitchen": "stay out of the kitchen"}.get)
    always = {realize(parse("G(!in_kitchen)"), realizer).rstrip(".").lower()
              for _ in range(100)}
    assert "always stay out of the kitchen" in always
    assert [s for s in always if "never" in s or "avoid" in s]  # the idiom stays too
    guarded = {realize(parse("G(wet -> !in_kitchen)"), realizer).rstrip(".").lower()
               for _ in range(200)}
    assert "stay out of the kitchen while the floor is wet" in guarded
    assert explain(parse("G(!in_kitchen)")) == "never in_kitchen"
    # "stay out of" lasts: never for a single instant without G
    once = {realize(parse("F(!in_kitchen)"), realizer).lower() for _ in range(100)}
    assert not [s for s in once if "stay out" in s]


def _sayings(formula: str, seeds: int = 200, **words) -> set[str]:
    f = parse(formula)
    return {realize(f, Realizer(rng=random.Random(seed), mode="train", **words))
            .rstrip(".").lower() for seed in range(seeds)}


def test_a_place_is_reached_for_good_or_again_and_again():
    """Tests the idioms over places: F(G(a)) "go to a and stay there", G(F(a)) "keep
    coming back to a", G(F(a)) & G(F(b)) "patrol between a and b"; a proposition that
    is no place keeps the compositional words."""
    places = {"at_dock": "the dock", "in_lab": "the lab"}
    words = {"say_atom": {"at_dock": "stay at the dock", "in_lab": "you are in the lab",
                          "door": "the door is open"}.__getitem__,
             "say_place": places.get}
    assert "go to the dock and stay there" in _sayings("F(G(at_dock))", **words)
    assert "keep coming back to the dock" in _sayings("G(F(at_dock))", **words)
    patrol = _sayings("G(F(at_dock)) & G(F(in_lab))", **words)
    assert "patrol between the dock and the lab" in patrol
    assert not [s for s in _sayings("F(G(door))", **words) if "there" in s]
    # The words are the first instant's: a bound or a nested G keeps them out
    assert not [s for s in _sayings("F[0,5](G(at_dock))", **words) if "stay there" in s]
    assert explain(parse("F(G(at_dock))")) == "eventually at_dock forever"


def test_a_state_kept_a_while_and_a_step_allowed_only_after_another():
    """Tests F(a & G[0,15](a)): "go to waypoint 3 and stay there for 15 steps" over a
    place, "hold the box for 15 steps at some point" over a lasting action, never "hold
    the box, and it stays so" (a command is no state); and the precedence
    (!b U a) & F(b): "screw on the cover, but only after the wires are connected", with
    a command that must come first said first, since "only after connect the wires" is
    no English, and only a command coming "first"."""
    words = {"say_atom": {"at_wp3": "be at waypoint 3", "wires": "the wires are connected",
                          "connect": "connect the wires", "hold": "hold the box",
                          "cover": "screw on the cover"}.__getitem__,
             "say_place": {"at_wp3": "waypoint 3"}.get,
             "is_action": lambda name: name in {"connect", "cover", "at_wp3", "hold"}}
    assert "go to waypoint 3 and stay there for 15 steps" in _sayings(
        "F(at_wp3 & G[0,15](at_wp3))", **words)
    held = _sayings("F(hold & G[0,15](hold))", **words)
    assert "hold the box for 15 steps at some point" in held
    assert not [s for s in held if "stays so" in s or "holds" in s or "from then on" in s]
    after = _sayings("(!cover U wires) & F(cover)", **words)
    assert "screw on the cover, but only after the wires are connected" in after
    assert not [s for s in after if s.startswith("first")]
    for first in ("connect", "!connect", "connect | wires"):
        said = _sayings(f"(!cover U ({first})) & F(cover)", **words)
        assert said and not [s for s in said if "after connect" in s or "after do not" in s
                             or "before connect" in s], first
    assert "connect the wires, and only after that screw on the cover" in _sayings(
        "(!cover U connect) & F(cover)", **words)


def test_only_if_and_only_when_follow_a_single_proposition():
    """Tests "a only if b" for a -> b and "a only when b" for G(a -> b), said only when
    a is a proposition: "p or q only if b" would read as binding q alone."""
    assert "a only if b" in _sayings("a -> b")
    assert {"a only when b", "a only while b"} <= _sayings("G(a -> b)")
    compound = _sayings("G((a | c) -> b)") | _sayings("(a | c) -> b")
    assert not [s for s in compound if " only " in s.replace("and only", "")]


def test_exactly_one_of_two_goals_says_each_goal_as_a_bare_command():
    """Tests "pick up the blue block or the green block, but not both": the goals of
    a choice are commands, without "please" or "you have to" in the middle."""
    words = {"say_atom": {"pick_blue": "pick up the blue block",
                          "pick_green": "pick up the green block"}.__getitem__,
             "is_action": lambda name: True}
    said = _sayings("(F(pick_blue) | F(pick_green)) & !(F(pick_blue) & F(pick_green))",
                    **words)
    assert "pick up the blue block or pick up the green block, but not both" in said
    assert not [s for s in said if "please" in s or "have to" in s]


def test_what_an_action_may_not_do_while_a_condition_holds():
    """Tests "never touch the pan while the stove is on" for G(stove_on -> !touch_pan):
    said of actions only, since "never the door is open while ..." is no sentence."""
    words = {"say_atom": {"stove_on": "the stove is on", "touch_pan": "touch the pan",
                          "door_open": "the door is open"}.__getitem__,
             "is_action": lambda name: name == "touch_pan"}
    said = _sayings("G(stove_on -> !touch_pan)", **words)
    assert {"never touch the pan while the stove is on",
            "do not touch the pan while the stove is on"} <= said
    assert "whenever the stove is on, do not touch the pan" in said  # the old words stay
    assert not [s for s in _sayings("G(stove_on -> !door_open)", **words)
                if s.startswith("never the door")]
    assert explain(parse("G(a -> !b)")) == "whenever a, not b"


def test_if_and_when_head_standing_rules_only_in_words():
    """Tests that "if a, b within 5 steps" is G(a -> F[0,5](b)) only where propositions
    are said in words: NL2TL's lifted sentences read "if (prop_1), (prop_2)" at the
    first instant, and the paper split is theirs."""
    for formula in ("G(a -> F[0,5](b))", "G(a -> F(b))", "G(a -> b)"):
        named, worded = set(), set()
        for seed in range(200):
            for in_words, said in ((False, named), (True, worded)):
                said.add(realize(parse(formula), Realizer(rng=random.Random(seed), mode="train",
                                                          in_words=in_words)).lower())
        assert not [t for t in named if re.match(r"(if|when) (?!ever)", t)], formula
        assert [t for t in worded if re.match(r"(if|when) (?!ever)", t)], formula
