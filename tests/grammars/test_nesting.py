"""Temporal operators nested: which pairs say something of note, which steps are ordered."""

from ara.grammars import parse, to_text
from ara.grammars.literal_edits import chained, operator_drops, unchained
from ara.grammars.nesting import (
    AFTER_WINDOW,
    AGAIN_AND_AGAIN,
    FOR_GOOD,
    HAPPENS,
    HOLDS,
    RESTATED,
    nested_pairs,
    orders_in_time,
    sequenced_steps,
    temporal_claims,
)
from ara.grammars.spot_bridge import equivalent


def pairs(stl: str) -> list[tuple[str, str]]:
    return [(to_text(node), kind) for node, kind in nested_pairs(parse(stl))]


def test_again_and_again_and_for_good_are_the_unbounded_pairs():
    assert pairs("G(F(a)) & F(G(b))") == [("G(F(a))", AGAIN_AND_AGAIN), ("F(G(b))", FOR_GOOD)]
    # "within 10 steps reach b and stay there" is for good too
    assert pairs("F[0,10](G(b))") == [("F[0,10](G(b))", FOR_GOOD)]


def test_pairs_whose_bounds_say_what_they_mean_are_not_named():
    # at least once in every 10 steps; at some point, a for 5 steps; both bounded
    assert pairs("G(F[0,10](a)) & F(G[0,5](b)) & F[0,3](F[2,4](c))") == []


def test_an_operator_inside_the_same_one_restates_it_or_voids_a_bound():
    for stl in ("F(F(a))", "G(G(a))", "F[10,25](F(a))", "G(G[0,5](a))"):
        assert [kind for _, kind in pairs(stl)] == [RESTATED], stl
    assert equivalent(parse("F[10,25](F(a))"), parse("F[10,25](a) | F[25,inf](a)"))


def test_a_window_of_g_over_an_unbounded_f_says_only_a_late_f():
    """"At every step of the first 45, a at some point later" asks no more than a at
    some point from step 45 on; a slip for "keep a on for 45 minutes" writes it."""
    assert pairs("G[0,45](F(a))") == [("G[0,45](F(a))", AFTER_WINDOW)]
    assert equivalent(parse("G[0,45](F(a))"), parse("F[45,inf](a)"))
    assert pairs("G[5,10](F(a))") == [("G[5,10](F(a))", AFTER_WINDOW)]
    # an open window (the decoding grammar writes none) is not this kind
    assert pairs("G[5,inf](F(a))") == []


def test_dropping_either_operator_of_a_pair():
    drops = {to_text(f) for f in operator_drops(parse("G(F(grip_bottle)) & F(at_dock)"),
                                                [parse("G(F(grip_bottle))")])}
    assert drops == {"F(grip_bottle) & F(at_dock)", "G(grip_bottle) & F(at_dock)"}
    # a node that is no pair, or not in the formula, gives nothing
    assert operator_drops(parse("G(a)"), [parse("G(a)"), parse("F(G(b))")]) == []


def test_steps_one_after_the_other_and_what_orders_in_time():
    assert [to_text(n) for n in sequenced_steps(parse("G(!c) & F(a & F(b))"))] == [
        "F(a & F(b))"]
    assert not list(sequenced_steps(parse("F(a) & F(b)")))
    for stl in ("F(a & F(b))", "!b U a", "G(a -> F(b))", "G(F(a))"):
        assert orders_in_time(parse(stl)), stl
    for stl in ("F(a) & F(b) & G(!c)", "G(a -> b)", "F[0,25](a) & F(b)"):
        assert not orders_in_time(parse(stl)), stl


def test_steps_are_freed_or_chained_as_written():
    """"Reach a and b in any order" read as a then b is freed; "a, then b, then c" read
    as three free steps is chained in the order the conjunction writes them, each step
    keeping its interval."""
    ordered = parse("G(!c) & F(a & F(b))")
    assert [to_text(f) for f in unchained(ordered, list(sequenced_steps(ordered)))] == [
        "G(!c) & (F(a) & F(b))"]
    chains = {to_text(f) for f in chained(parse("(F(m) & F[0,25](c)) & F(g)"))}
    assert "F(m & F[0,25](c & F(g)))" in chains
    for chain in chains:
        assert orders_in_time(parse(chain))
    assert chained(parse("F(a) & G(b)")) == []  # one step: nothing to order


def test_what_a_formula_claims_over_time_read_as_written_and_through_negations():
    def claims(stl: str) -> set[str]:
        return set(temporal_claims(parse(stl)))

    assert claims("G(F(a))") == {HOLDS, HAPPENS, AGAIN_AND_AGAIN}
    assert claims("F[10,20](door_locked)") == {HAPPENS}
    assert claims("G[0,10](a)") == {HOLDS}
    assert claims("!(a & b)") == set()  # "never both" needs a G this lacks
    assert claims("!F(a)") == {HOLDS, HAPPENS}  # G(!a), written with an F
    assert claims("G(a -> F[0,5](b))") == {HOLDS, HAPPENS, AGAIN_AND_AGAIN}
    assert claims("a U b") == {HOLDS, HAPPENS}
    # "every so often" is no G over a proposition, nor "stay there" an F alone
    assert AGAIN_AND_AGAIN not in claims("G(inspect_forklift)")
    assert HOLDS not in claims("F(drop_package & F(at_charging_station))")
