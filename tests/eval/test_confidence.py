"""How sure the shipped fine-tune is of its answers: the flag `ara translate` raises."""

import math

import pytest

from ara.eval.translate.confidence import (
    DOUBT,
    answer_probability,
    doubt_warning,
    winner_probability,
)
from ara.eval.translate.translator import Translator

from conftest import DOUBTED


@pytest.fixture(scope="module")
def translator(finetuned):
    return Translator(finetuned)


def test_the_model_is_sure_of_a_sentence_it_reads_and_doubts_one_it_cannot(translator):
    """Tests that the probability of the greedy answer is high for a plain instruction,
    low for a wrong reading of it, and low for a garbled request."""
    nl, aps = "at no time ( prop_1 )", ("prop_1",)
    answer = translator.translate(nl, aps).stl
    assert answer == "G(!prop_1)"
    assert answer_probability(translator, nl, aps, answer) > 0.8  # 0.99 for the shipped file
    assert answer_probability(translator, nl, aps, "F(prop_1)") < DOUBT
    garbled, pair = DOUBTED
    probability = answer_probability(translator, garbled, pair,
                                     translator.translate(garbled, pair).stl)
    assert 0 < probability < DOUBT
    assert answer_probability(translator, nl, aps, None) is None  # no answer, nothing to score


@pytest.mark.slow  # repair on test_finetuned's sentence again, 9 answers scored
def test_a_repaired_answer_is_scored_as_if_asked_anew(translator):
    """Tests that the winner's probability taken from repair's scores is the one scoring
    it afresh gives (a batch rounds differently from feeding a token at a time, so
    within 0.1 nats), on a request repair acts on."""
    from ara.eval.translate.repair import RepairConfig, translate_repaired

    nl = "Bring pallet 8 to the loading dock within 250 steps and pallet 9 within 400 steps."
    aps = ("deliver_pallet_8", "deliver_pallet_9")
    vote = translate_repaired(translator, nl, aps, repair=RepairConfig(8))
    if len(vote.results) == 1:
        pytest.skip(f"the greedy answer {vote.result.stl} leaves nothing out: no repair")
    from_vote = winner_probability(translator, vote)
    afresh = answer_probability(translator, nl, aps, vote.result.stl)
    assert abs(math.log(from_vote) - math.log(afresh)) < 0.1


def test_the_note_reads_the_answer_back():
    """Tests the note's wording: the probability, the threshold, the English reading."""
    note = doubt_warning("F(a & F(b))", 0.0123)
    assert note.startswith("note: the model gives this answer a probability of 0.012;")
    assert f"below {DOUBT:g}" in note and 'It reads: "first a, then b".' in note
    with_others = doubt_warning("F(a & F(b))", 0.4, [("F(a) & F(b)", 0.35)])
    assert "or take one of the other readings it weighed:" in with_others
    assert with_others.splitlines()[1] == (
        '  F(a) & F(b)  (probability 0.35): "eventually a, and eventually b"')


def test_decoding_scores_its_answer_on_the_way(translator):
    """Tests that the log-probability decoding sums while it writes an answer is the
    one scoring the answer afterwards gives, so the check on every answer costs no
    second pass (within 0.75 nats: llama.cpp multiplies a batch by the quantized
    weights with other kernels than one token; at most 0.17 apart with the shipped
    file, 0.51 with an earlier one)."""
    from ara.grammars import parse

    for nl, aps in [("at no time ( prop_1 )", ("prop_1",)),
                    ("Keep away from the stairs at all times and eventually reach the garden.",
                     ("at_garden", "at_stairs")),
                    DOUBTED]:
        result = translator.translate(nl, aps)
        assert result.logprob is not None, result.raw  # the tokenizer's own tokens
        scored = translator.score(nl, aps, [parse(result.stl)])[0]
        assert result.logprob == pytest.approx(scored, abs=0.75)
    free = translator.translate("at no time ( prop_1 )", ("prop_1",), constrained=False)
    assert free.logprob is None  # free decoding stops at the newline it does not keep
