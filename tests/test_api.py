"""`import ara`: the toolkit from Python, as its command line has it."""

import doctest

import pytest

import ara
from ara.errors import AraError

from conftest import needs_llama


def test_read_back_and_compare_formulas_given_as_text():
    """Tests ara.explain and ara.equivalent on the README's formulas."""
    assert ara.explain("G(battery_low -> F[0,30](at_charger)) & G(!in_wet_aisle)") == (
        "whenever battery_low, at_charger within 30 steps, and never in_wet_aisle")
    assert ara.equivalent("G(!(a | b))", "G(!a) & G(!b)")
    assert not ara.equivalent("F(a & F(b))", "F(a) & F(b)")
    with pytest.raises(AttributeError, match="has no attribute 'translat'"):
        ara.translat  # noqa: B018  (a typo gets Python's own error, not a lazy import)


def test_a_request_the_command_refuses_is_refused_before_loading_a_model():
    """Tests that ara.translate checks the request as `ara translate` does."""
    with pytest.raises(AraError, match="the instruction is empty"):
        ara.translate("  ", ["enter_lab"], model="no-such-model")
    with pytest.raises(AraError, match="never mentions open_door"):
        ara.translate("never enter the lab", ["enter_lab", "open_door"], model="no-such-model")


@needs_llama
def test_translate_gives_the_command_s_answer_and_keeps_the_model_loaded():
    """Tests ara.translate with the shipped fine-tune: the typed answer, the model
    loaded once for two calls and shared by translators of other settings, and the
    module's own examples."""
    ara.translator.cache_clear()
    answer = ara.translate("Never enter the server room.", ["enter_server_room"])
    assert answer.stl == "G(!enter_server_room)" and answer.result.valid
    assert answer.confidence > 0.9 and answer.alternatives == ()
    assert not answer.gaps
    assert answer.to_json()["left_out"] == {"aps": [], "numbers": [], "order": False,
                                            "claims": []}
    timed = ara.translate("within 20 steps reach ( prop_1 )", ["prop_1"], repair=0)
    assert timed.stl == "F[0,20](prop_1)" and timed.vote is None  # greedy
    assert ara.translator.cache_info().misses == 1  # one load for both
    # other settings, and the command line's own path, share the model loaded
    from ara.eval.translate.models import shared_backend
    from ara.eval.translate.translator import TranslatorConfig

    untimed = ara.translator("finetuned", TranslatorConfig(intervals=False))
    assert untimed.backend is ara.translator("finetuned", None).backend
    assert untimed.backend is shared_backend("finetuned")
    assert doctest.testmod(ara.api).failed == 0
