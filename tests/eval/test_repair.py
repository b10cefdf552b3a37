"""Semantic self-consistency: answers vote by meaning, and the greedy one breaks ties."""

from __future__ import annotations

import math
import time

import pytest

from ara.errors import ConfigError
from ara.eval.translate.backends.base import BackendError, Sampling
from ara.eval.translate.checks import gaps
from ara.eval.translate.deadline import UNBOUNDED, Deadline
from ara.eval.translate.repair import (
    RepairConfig,
    Vote,
    _group,
    _missing,
    _same,
    literal_mends,
    rank_repairs,
    readings,
    translate_consistent,
    translate_repaired,
)
from ara.eval.translate.request import Request
from ara.eval.translate.translator import TranslationResult, Translator, TranslatorConfig
from ara.grammars import parse

from conftest import DOUBTED, needs_llama


def test_answers_group_by_meaning_not_by_text():
    """Tests that Spot-equivalent spellings share a group and unparsed answers stand alone."""
    answers = ("F(a) | F(b)", "G(a)", "F(a | b)", None, "G(a)")
    assert _group(answers, timeout_s=10) == [(0, 2), (1, 4), (3,)]
    # A bound Spot cannot check (--max-bound lets a user allow one) stands alone.
    assert _group(("F[0,1500](a)", "F(a)"), timeout_s=10) == [(0,), (1,)]


def _answer(stl: str) -> TranslationResult:
    return TranslationResult(
        nl="a or b at some point", aps=("a", "b"), raw=" " + stl, stl=stl, valid=True,
        error=None, constrained=True, grammar_in_prompt=False, shots=0, prompt_sha256="",
        prompt_tokens=0, completion_tokens=0, cached_tokens=0, ms=0.0, stop="eos",
        masked_steps=0)


def test_readings_are_the_distinct_meanings_best_scored_first():
    """Tests the readings `ara translate --alternatives` lists: one per meaning, as its
    best-scored spelling, in the vote's order; answers repair did not score (they leave
    out more) are not readings."""
    texts = ("F(a | b)", "F(a) | F(b)", "G(a)", "F(a) | b", "G(a)")
    scores = (-0.9, -0.5, -1.2, None, -1.2)
    vote = Vote(tuple(map(_answer, texts)), ((1,), (0,), (2, 4), (3,)), 0.0, scores)
    assert readings(vote, timeout_s=10) == [("F(a) | F(b)", -0.5), ("G(a)", -1.2)]
    assert readings(vote, timeout_s=10, limit=1) == [("F(a) | F(b)", -0.5)]
    greedy_only = Vote((_answer("G(a)"),), ((0,),), 0.0)  # nothing scored
    assert readings(greedy_only) == []


def spent_deadline() -> Deadline:
    """A budget of one second, started two seconds ago."""
    return Deadline(1.0, start=time.perf_counter() - 2.0)


def test_spot_checks_stop_when_the_budget_is_spent():
    """Tests that a spent budget answers 'not the same' without asking Spot (equal texts
    still are), so that grouping leaves each meaning alone, and says it ran out."""
    deadline = spent_deadline()
    assert _same("G(a)", "G(a)", 10.0, deadline) and not deadline.ran_out
    assert not _same("F(a) | F(b)", "F(a | b)", 10.0, deadline) and deadline.ran_out
    answers = ["F(a) | F(b)", "F(a | b)", "F(a) | F(b)"]
    assert _group(answers, 10.0, spent_deadline()) == [(0, 2), (1,)]
    assert _group(answers, 10.0, UNBOUNDED) == [(0, 1, 2)]


def test_readings_stop_at_the_winner_when_the_budget_is_spent():
    """Tests that a spent budget lists the winner's reading (no Spot check needed) and
    no other."""
    vote = Vote((_answer("F(a) | F(b)"), _answer("G(a)")), ((0,), (1,)), 0.0, (-0.5, -1.2))
    deadline = spent_deadline()
    assert readings(vote, 10.0, deadline=deadline) == [("F(a) | F(b)", -0.5)]
    assert deadline.ran_out
    assert len(readings(vote, 10.0)) == 2


def test_sampling_settings_are_checked():
    """Tests that a zero temperature (greedy in disguise) is refused with the fix."""
    with pytest.raises(BackendError, match="pass no Sampling"):
        Sampling(temperature=0)


# The base model's long samples; seeded samples are checked by the vote's
# reproducibility in the default tier (and the prefix-reuse test in the slow one).
@pytest.mark.slow
@needs_llama
def test_sampled_answers_are_valid_seeded_and_varied(llama_backend):
    """Tests that sampling under the grammar keeps every answer valid, that a seed fixes
    the answer, and that seeds give different answers."""
    t = Translator(llama_backend)
    aps = ("prop_1", "prop_2")
    nl = "whenever (prop_1), eventually (prop_2)"
    draws = [t.translate(nl, aps, sampling=Sampling(1.0, seed)).stl for seed in range(6)]
    assert all(d is not None for d in draws)
    assert t.translate(nl, aps, sampling=Sampling(1.0, 3)).stl == draws[3]
    assert len(set(draws)) > 1


@needs_llama
def test_one_sample_is_greedy_and_the_vote_is_reproducible(llama_backend):
    """Tests that samples=1 is the greedy answer, and that the winner belongs to the
    largest group, ties going to the greedy answer."""
    t = Translator(llama_backend)
    aps = ("prop_1",)
    nl = "always eventually (prop_1)"
    greedy = t.translate(nl, aps).stl
    assert translate_consistent(t, nl, aps, samples=1).result.stl == greedy
    vote = translate_consistent(t, nl, aps, samples=4, temperature=1.0, seed=7)
    again = translate_consistent(t, nl, aps, samples=4, temperature=1.0, seed=7)
    assert (again.answers, again.groups) == (vote.answers, vote.groups)
    assert sorted(i for g in vote.groups for i in g) == [0, 1, 2, 3]
    assert vote.result.stl == vote.answers[vote.groups[0][0]]
    assert len(vote.groups[0]) == max(len(g) for g in vote.groups)
    with pytest.raises(ConfigError, match="samples must be >= 1"):
        translate_consistent(t, nl, aps, samples=0)


def test_repair_keeps_greedy_unless_a_sample_leaves_out_less():
    """Tests the ranking of repaired answers: the greedy answer (index 0) wins while no
    sample says more of the request; otherwise the majority of the most complete ones."""
    answers = ("F(a)", "F(a) & G(!b)", "G(!b) & F(a)", "F(a | b)", "F(a)")
    assert rank_repairs(answers, [1, 1, 1, 1, 1])[0] == (0, 4)
    assert rank_repairs(answers, [1, 0, 0, 0, 1])[0] == (1, 2)
    assert rank_repairs(answers, [1, 0, 0, 0, 1])[1] == (3,)
    assert rank_repairs(answers, [0, 0, 0, 0, 0])[0] == (0, 4)


# The base model's long samples; when repair draws is tested on the shipped model below
# (test_repair_searches_again_only_where_the_model_doubts_a_complete_answer).
@pytest.mark.slow
@needs_llama
def test_repair_draws_only_for_an_answer_with_a_gap(llama_backend):
    """Tests that repair draws extra answers exactly when the greedy one leaves part of
    the request out, that its winner leaves out no more than greedy, and that it is
    reproducible."""
    t = Translator(llama_backend)
    aps = ("prop_1", "prop_2")
    nl = "within 20 steps reach (prop_1), and never (prop_2)"
    greedy = t.translate(nl, aps)
    greedy_gaps = len(gaps(Request.of(nl, aps), parse(greedy.stl)))
    drawn = RepairConfig(3, "samples", temperature=1.0, seed=5)
    vote = translate_repaired(t, nl, aps, repair=drawn)
    assert vote.answers[0] == greedy.stl
    assert len(vote.results) == (4 if greedy_gaps else 1)
    assert len(gaps(Request.of(nl, aps), parse(vote.result.stl))) <= greedy_gaps
    again = translate_repaired(t, nl, aps, repair=drawn)
    assert (again.answers, again.groups) == (vote.answers, vote.groups)
    assert translate_repaired(t, nl, aps, repair=RepairConfig(0)).answers == (greedy.stl,)
    with pytest.raises(ConfigError, match="repair draws 0 to 32 answers"):
        RepairConfig(-1)
    with pytest.raises(ConfigError, match=r"choose one of samples\+edits, edits, samples"):
        RepairConfig(by="votes")
    with pytest.raises(ConfigError, match=r"doubt is a probability, 0 to 1 \(0: gaps only\)"):
        RepairConfig(doubt=2)


@needs_llama
@pytest.mark.parametrize("by", ["samples+edits", "edits"])
def test_repair_by_score_keeps_the_best_scored_complete_answer(llama_backend, by):
    """Tests repair by the model's score on an answer that leaves a bound out: it weighs
    the greedy answer, the samples drawn (with samples+edits) and every formula one edit
    away that writes what was left out; it scores exactly those that leave out least, as
    the model scores each alone, and keeps the best."""
    t = Translator(llama_backend)
    aps = ("prop_1", "prop_2")
    nl = "within 20 steps reach (prop_1), and never (prop_2)"
    greedy = t.translate(nl, aps)
    left_out = gaps(Request.of(nl, aps), parse(greedy.stl))
    assert left_out, f"{greedy.stl} leaves nothing out: choose a sentence it leaves a bound out of"
    vote = translate_repaired(t, nl, aps, repair=RepairConfig(3, by))
    mends = literal_mends(t, Request.of(nl, aps), greedy.stl)
    drawn = 3 if by == "samples+edits" else 0
    assert vote.answers[0] == greedy.stl and vote.answers[1 + drawn:] == tuple(mends)
    missing = [len(gaps(Request.of(nl, aps), parse(a))) for a in vote.answers]
    scored = [i for i, x in enumerate(vote.scores) if x is not None]
    assert scored == [i for i, m in enumerate(missing) if m == min(missing)]
    winner = vote.groups[0][0]
    assert winner in scored and vote.scores[winner] == max(vote.scores[i] for i in scored)
    assert sorted(i for g in vote.groups for i in g) == list(range(len(vote.answers)))
    assert all(len({vote.answers[i] for i in g}) == 1 for g in vote.groups)  # by text
    assert missing[winner] < len(left_out)
    assert t.score(nl, aps, [parse(vote.result.stl)])[0] == pytest.approx(vote.scores[winner],
                                                                         abs=0.2)


@needs_llama
def test_mends_drop_the_operators_a_sentence_never_asks_for(llama_backend):
    """Tests the mends of an answer that nests operators unasked: "reach the dock
    within 200 steps" asks neither for staying there nor for one F inside another, so
    each is dropped, the second after the first, and nothing else is proposed."""
    t = Translator(llama_backend)
    nl, aps = "Reach the dock within 200 steps.", ("at_dock",)
    assert gaps(Request.of(nl, aps), parse("F[0,200](F(G(at_dock)))")).unasked == (
        "F[0,200](F(G(at_dock)))", "F(G(at_dock))")
    mends = literal_mends(t, Request.of(nl, aps), "F[0,200](F(G(at_dock)))")
    assert {"F[0,200](at_dock)", "F[0,200](G(at_dock))", "F(G(at_dock))"} <= set(mends)
    assert "F[0,200](F(G(at_dock)))" not in mends
    assert literal_mends(t, Request.of(nl, aps), "F[0,200](at_dock)") == []


@needs_llama
def test_mends_order_steps_the_sentence_orders_and_free_those_it_does_not(llama_backend):
    """Tests the mends of an answer that misses the order of its steps either way."""
    t = Translator(llama_backend)
    nl, aps = "Charge the battery, and afterwards return to the dock.", ("charge", "at_dock")
    mends = literal_mends(t, Request.of(nl, aps), "F(charge) & F(at_dock)")
    assert "F(charge & F(at_dock))" in mends
    nl = "Water the plants and feed the cat, in either order."
    aps = ("water_plants", "feed_cat")
    assert "F(water_plants) & F(feed_cat)" in literal_mends(
        t, Request.of(nl, aps), "F(water_plants & F(feed_cat))")


def test_without_intervals_every_gap_but_a_bound_counts():
    """Tests that with --no-intervals an order, a claim or a nesting left out or added is
    still a reason to repair, and only a bound, which no answer could write, is not."""
    request = Request.of("Go to the mailroom, then always stay in the gym, within 5 steps.",
                         ("go_to_mailroom", "at_gym"))
    answer = "F(go_to_mailroom) & F(at_gym)"  # no order, no G, no 5
    assert _missing(request, answer, bounds=True) == 3
    assert _missing(request, answer, bounds=False) == 2
    assert _missing(request, "F(go_to_mailroom & F(G(at_gym)))", bounds=False) == 0
    assert _missing(request, "F(F(go_to_mailroom & F(G(at_gym))))", bounds=False) == 1


@needs_llama
def test_repair_does_not_draw_for_a_bound_no_answer_can_write(llama_backend):
    """Tests that without intervals a stated bound is no reason to draw: no answer of
    the grammar could write it."""
    t = Translator(llama_backend, TranslatorConfig(intervals=False))
    nl, aps = "reach (prop_1) within 5 steps", ("prop_1",)
    vote = translate_repaired(t, nl, aps, repair=RepairConfig(3, doubt=0))  # gaps only
    left_out = gaps(Request.of(nl, aps), parse(vote.answers[0]))
    assert left_out.numbers == (5,)
    assert len(vote.results) == (4 if left_out.count(timed=False) else 1)


def test_repair_searches_again_only_where_the_model_doubts_a_complete_answer(finetuned):
    """Tests repair on answers that leave nothing out: one the model is sure of stands,
    scored once; one it gives a probability below ``doubt`` is weighed against the
    samples drawn, and the best-scored complete answer wins, never one the model scores
    lower than the greedy answer."""
    t = Translator(finetuned)
    sure = translate_repaired(t, "at no time ( prop_1 )", ("prop_1",),
                              repair=RepairConfig(4))
    assert sure.answers == ("G(!prop_1)",) and math.exp(sure.scores[0]) > 0.9
    nl, aps = DOUBTED
    doubted = translate_repaired(t, nl, aps, repair=RepairConfig(4, doubt=0.5))
    assert len(doubted.answers) == 5 and not gaps(Request.of(nl, aps), parse(doubted.answers[0]))
    assert math.exp(doubted.scores[0]) < 0.5
    best = max(s for s in doubted.scores if s is not None)
    assert doubted.scores[doubted.groups[0][0]] == best >= doubted.scores[0]
    gaps_only = RepairConfig(4, doubt=0)
    assert translate_repaired(t, nl, aps, repair=gaps_only).answers == doubted.answers[:1]
