"""A request's grammar: its propositions, and the time bounds its sentence writes."""

import pytest

from ara.data import load_or_prepare
from ara.eval.translate.translator import TranslatorConfig, decoding_grammar
from ara.grammars import build_grammar
from ara.grammars.ast import walk


def test_a_sentence_without_numbers_gets_no_interval_at_all():
    syntax = TranslatorConfig().syntax(("door",), "always avoid the door")
    assert not syntax.intervals
    assert not syntax.accepts("G[0,5](!door)") and syntax.accepts("G(!door)")


def test_intervals_use_only_zero_and_the_sentences_numbers():
    syntax = TranslatorConfig().syntax(("door",), "reach the door between step 5 and step 9")
    assert syntax.bounds == (0, 5, 9)
    assert syntax.accepts("F[5,9](door)") and syntax.accepts("F[0,9](door)")
    assert not syntax.accepts("F[5,10](door)")   # 10 is not in the sentence
    assert not syntax.accepts("F[9,5](door)")    # nor is an empty interval
    # Off, any bound up to max_bound is admitted, as before.
    free = TranslatorConfig(bounds_from_request=False).syntax(("door",), "reach the door")
    assert free.bounds is None and free.accepts("F[5,10](door)")


def test_the_listed_grammar_is_a_small_fraction_of_the_full_one():
    """Why: the full interval trie is two rules per number up to 1000, which llguidance
    compiles again for every new set of propositions."""
    config = TranslatorConfig()
    listed = build_grammar(config.syntax(("door",), "within 20 steps reach the door"))
    full = build_grammar(TranslatorConfig(bounds_from_request=False).syntax(("door",)))
    assert len(decoding_grammar(listed).grammar.to_lark()) * 20 < \
        len(decoding_grammar(full).grammar.to_lark())


@pytest.mark.parametrize("split,part", [("timed", "test"), ("handwritten", "test")])
def test_every_timed_reference_fits_its_own_sentences_grammar(split, part):
    """The rule loses no reference answer of the timed evaluation sets (the depth and
    width limits aside: a nested ``(a & b) & c`` is how the grammar writes ``a & b & c``)."""
    config = TranslatorConfig(max_depth=99, max_args=99)
    records = load_or_prepare(split).records(part)
    timed = [r for r in records if any(getattr(n, "interval", None) for n in walk(r.formula))]
    assert len(timed) >= 50
    misfits = [r.nl for r in records if not config.syntax(r.aps, r.nl).accepts(r.stl)]
    assert misfits == []
