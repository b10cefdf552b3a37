"""One answer to a request, as every way in gives it: ara.eval.translate.answering."""

import pytest

from ara.errors import ConfigError
from ara.eval.translate.answering import Answer, AnswerConfig, answer, notes
from ara.eval.translate.checks import gaps
from ara.eval.translate.repair import RepairConfig, Vote
from ara.eval.translate.request import Request
from ara.eval.translate.translator import TranslationResult, Translator
from ara.grammars import parse

from conftest import DOUBTED

#: The keys of `ara translate --json`, in the order translate-file writes them
#: (Answer.to_json's docstring, docs/evaluation.md).
DOCUMENTED_KEYS = ["stl", "valid", "raw", "ms", "budget", "error", "model", "constrained",
                   "shots", "grammar", "samples", "confidence", "alternatives", "left_out",
                   "unasked", "condition"]


def _result(stl: str, nl: str = "( prop_1 ) or ( prop_2 ) at some point") -> TranslationResult:
    return TranslationResult(
        nl=nl, aps=("prop_1", "prop_2"), raw=" " + stl, stl=stl, valid=True, error=None,
        constrained=True, grammar_in_prompt=False, shots=0, prompt_sha256="",
        prompt_tokens=0, completion_tokens=0, cached_tokens=0, ms=12.34, stop="eos",
        masked_steps=0)


def test_the_json_of_an_answer_has_the_documented_keys_in_order():
    """Tests that to_json writes the documented keys in their order: samples only where
    answers were weighed, the gaps only where the answer parses."""
    nl, winner = "( prop_1 ) or ( prop_2 ) at some point", "F(prop_1 | prop_2)"
    vote = Vote((_result(winner), _result("F(prop_1) | prop_2")), ((0,), (1,)), 56.78,
                (-0.832, -0.893))
    found = gaps(Request.of(nl, ("prop_1", "prop_2")), parse(winner))
    answer = Answer(vote.result, "m", vote, 0.435, (("F(prop_1) | prop_2", 0.409),), found)
    data = answer.to_json()
    assert list(data) == DOCUMENTED_KEYS
    assert data["ms"] == 56.8 and answer.attempts == 2  # the whole vote's time
    assert data["samples"] == {"answers": [winner, "F(prop_1) | prop_2"],
                               "groups": [[0], [1]], "agreement": 0.5,
                               "scores": [-0.832, -0.893]}
    assert data["alternatives"] == [{"stl": "F(prop_1) | prop_2", "probability": 0.409}]
    greedy = Answer(_result(winner), "m").to_json()
    assert [k for k in DOCUMENTED_KEYS if k not in greedy] == ["samples", "left_out",
                                                              "unasked", "condition"]
    assert greedy["ms"] == 12.3 and greedy["confidence"] is None
    assert greedy["budget"] == {"s": None, "ran_out": False}
    waited = Answer(vote.result, "m", vote, waited_ms=98.76, budget_s=5.0, ran_out=True)
    assert waited.to_json()["ms"] == 98.8  # what the user waited, not the vote's time
    assert waited.to_json()["budget"] == {"s": 5.0, "ran_out": True}


def test_notes_read_the_typed_answer():
    """Tests that a doubted answer gets the note with the readings weighed, and a sure
    one with no gap gets nothing."""
    doubted = Answer(_result("F(prop_1 | prop_2)"), "m", confidence=0.435,
                     alternatives=(("F(prop_1) | prop_2", 0.409),))
    [note] = notes(doubted, "( prop_1 ) or ( prop_2 ) at some point")
    assert note.startswith("note: the model gives this answer a probability of 0.43;")
    assert "F(prop_1) | prop_2  (probability 0.41)" in note
    assert notes(Answer(_result("F(prop_1 | prop_2)"), "m", confidence=0.99)) == []


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"repair": 33}, "repair draws 0 to 32 answers"),  # above the range
        ({"repair_by": "votes"}, r"--repair-by 'votes'\? choose one of samples"),  # unknown
        ({"doubt": 1.5}, r"doubt is a probability, 0 to 1 \(0: gaps only\); got 1.5"),
        ({"temperature": 0}, "temperature must be > 0"),  # a division by zero later
        ({"samples": 3, "repair": 2}, "two ways to spend extra answers; pass one"),
        ({"repair": 2, "constrained": False}, "--repair decodes under the grammar"),
        ({"budget_s": -1}, r"the budget is seconds per answer, >= 0 \(0: unbounded\)"),
        ({"budget_s": float("inf")}, "got inf"),  # unbounded is 0, not a number
    ],
)
def test_bad_answer_options_are_refused_with_the_fix(options, message):
    """Tests that the options of `ara translate` are checked where the configs are built."""
    with pytest.raises(ConfigError, match=message):
        AnswerConfig.of(**options)


def test_repair_defaults_to_on_unless_answers_are_voted_or_unconstrained():
    """Tests the resolved number of answers repair draws."""
    assert AnswerConfig().repairs == 8
    assert AnswerConfig(samples=3).repairs == 0
    assert AnswerConfig(constrained=False).repairs == 0
    assert AnswerConfig(repair=RepairConfig(0)).repairs == 0


def test_an_answer_out_of_time_is_the_greedy_one_and_says_so(finetuned):
    """Tests that a budget spent before repair can act gives the greedy answer, valid
    and checked for gaps, says it ran out, and counts in ms the whole wait."""
    t = Translator(finetuned)
    greedy = t.translate(*DOUBTED)
    hurried = answer(t, *DOUBTED, config=AnswerConfig.of(budget_s=0.001))
    assert hurried.stl == greedy.stl and hurried.result.valid
    assert hurried.vote.answers == (greedy.stl,) and hurried.gaps is not None
    assert hurried.ran_out and hurried.to_json()["budget"] == {"s": 0.001, "ran_out": True}
    assert hurried.ms >= hurried.result.ms
    assert "ran out" in " ".join(notes(hurried, DOUBTED[0]))


def test_an_unbounded_answer_never_runs_out(finetuned):
    """Tests that without a budget (0) repair draws every answer it would, and the
    answer never says it ran out."""
    unbounded = answer(Translator(finetuned), *DOUBTED, config=AnswerConfig.of(repair=4,
                                                                             budget_s=0))
    assert len(unbounded.vote.answers) == 5  # the greedy one and the four drawn
    assert not unbounded.ran_out
    assert unbounded.to_json()["budget"] == {"s": None, "ran_out": False}
    assert not any("ran out" in note for note in notes(unbounded, DOUBTED[0]))
