"""The llama.cpp backend on the embedded model: constraint, prefix reuse, both mask engines."""

import random

import numpy as np
import pytest

from ara.errors import ConfigError
from ara.eval.translate.backends.base import BackendError, Sampling
from ara.eval.translate.backends.masking import allowed_tokens
from ara.eval.translate.prompt import STOP, build_prompt, sample_shots
from ara.eval.translate.translator import Translator, TranslatorConfig
from ara.grammars import Syntax, build_grammar, parse
from ara.grammars.ast import interval_of, walk


def test_allowed_tokens_unpacks_an_llguidance_bitmask():
    """Tests bit i of word w meaning token 32*w + i."""
    mask = np.zeros(4, dtype=np.int32)
    mask[0] = 0b101  # tokens 0 and 2
    mask[2] = np.int32(-(2**31))  # bit 31 of word 2: token 95
    assert allowed_tokens(mask, 128).tolist() == [0, 2, 95]
    assert allowed_tokens(mask, 90).tolist() == [0, 2]  # beyond the vocabulary: dropped


def test_missing_model_file_is_a_clear_error(tmp_path):
    """Tests the message for a GGUF path that does not exist."""
    from ara.eval.translate.backends.llama_cpp_backend import LlamaCppBackend

    with pytest.raises(BackendError, match="model file not found"):
        LlamaCppBackend(str(tmp_path / "missing.gguf"))


def decoding_grammar(aps, **kwargs):
    """The translator's own decoding grammar for ``aps``."""
    from ara.eval.translate.translator import decoding_grammar as translator_grammar

    return translator_grammar(build_grammar(Syntax(aps=tuple(aps), max_depth=5, max_args=2,
                                                   **kwargs)))


# 20 answers: every constrained answer is checked against the grammar as it is made,
# and the tests below generate under it in the default tier.
@pytest.mark.slow
def test_constrained_outputs_always_belong_to_the_language(llama_backend, paper_split):
    """Tests the guarantee on real generations: 0 and 5 shots, lifted and grounded,
    with and without the grammar in the prompt; every output is in the language."""
    translator = Translator(llama_backend)
    rng = random.Random(0)
    for form in ("lifted", "grounded"):
        examples = sample_shots(paper_split.records("train", form), 5, rng)
        records = rng.sample(paper_split.records("test", form), 5)
        for shots in (examples, ()):  # outer loop: consecutive prompts share a prefix
            for record in records:
                # the grammar in the prompt depends on the propositions: for grounded
                # records it would defeat prefix reuse, so show it on lifted ones
                result = translator.translate(record.nl, record.aps, shots,
                                              grammar_in_prompt=not shots and form == "lifted")
                assert result.valid and result.stop == "eos", result
                assert translator.config.syntax(record.aps).accepts(result.stl)


def test_constrained_timed_outputs_respect_interval_bounds(llama_backend):
    """Tests the guarantee with intervals: every bound an answer writes stays within
    max_bound, lo <= hi. (The base model writes no interval unasked, so each answer is
    required to write the sentence's last number.)"""
    translator = Translator(llama_backend, TranslatorConfig(intervals=True, max_bound=60))
    for nl, last in (("within 10 to 20 seconds reach (prop_1) and always avoid (prop_2)", "20"),
                     ("(prop_1) until (prop_2) between steps 3 and 9", "9")):
        result = translator.translate(nl, ("prop_1", "prop_2"), require=(last,))
        assert result.valid and translator.config.syntax(("prop_1", "prop_2"),
                                                         nl).accepts(result.stl), result
        intervals = [iv for node in walk(parse(result.stl)) if (iv := interval_of(node))]
        assert intervals and all(iv.hi is not None and iv.lo <= iv.hi <= 60
                                 for iv in intervals), result


def test_an_answer_can_be_required_to_write_what_the_request_lists(llama_backend):
    """Tests ``require`` on real generations: every answer names the required
    proposition and bound, and stays in the request's language."""
    from ara.grammars import atoms, parse, walk

    translator = Translator(llama_backend)
    nl = "reach (prop_1) within 12 steps, and never (prop_2) or (prop_3)"
    aps = ("prop_1", "prop_2", "prop_3")
    for require in (("prop_3",), ("prop_2", "12")):
        result = translator.translate(nl, aps, require=require)
        formula = parse(result.stl)
        bounds = {str(b) for node in walk(formula) if (iv := interval_of(node))
                  for b in (iv.lo, iv.hi)}
        assert set(require) <= atoms(formula) | bounds, result.stl
        assert translator.config.syntax(aps, nl).accepts(result.stl)
    with pytest.raises(ConfigError, match="cannot require 7"):  # not a bound of the sentence
        translator.translate(nl, aps, require=("7",))


@pytest.mark.slow  # a speed-up's equivalence; generation under the grammar runs in the default tier
def test_prefix_reuse_changes_nothing_but_the_work(llama_backend, embedded_model_path,
                                                   paper_split):
    """Tests that a prompt sharing its prefix with the previous one gets exactly what a
    fresh model gives it (text, log-probability, seeded samples, scores), while
    evaluating fewer prompt tokens: an answer does not depend on what came before."""
    from ara.eval.translate.backends.llama_cpp_backend import LlamaCppBackend

    shots = sample_shots(paper_split.records("train", "lifted"), 5, random.Random(1))
    tests = paper_split.records("test", "lifted")[:3]
    prompts = [build_prompt(r.nl, r.aps, shots) for r in tests]
    grammars = [decoding_grammar(r.aps) for r in tests]

    def answers(backend, prompt, grammar):
        greedy = backend.complete(prompt, grammar, 32, STOP)
        drawn = [backend.complete(prompt, grammar, 32, STOP, Sampling(1.0, seed=k))
                 for k in range(2)]
        scores = backend.score(prompt, [greedy.text + STOP, " G(prop_1)" + STOP])
        return greedy, [(c.text, c.logprob) for c in drawn], scores

    warm = [answers(llama_backend, *pg) for pg in zip(prompts, grammars, strict=True)]
    assert warm[1][0].cached_tokens > 0.8 * warm[1][0].prompt_tokens
    for prompt, grammar, (greedy, drawn, scores) in zip(prompts, grammars, warm, strict=True):
        fresh = answers(LlamaCppBackend(embedded_model_path, n_ctx=4096), prompt, grammar)
        assert fresh[0].cached_tokens == 0
        assert (fresh[0].text, fresh[0].logprob) == (greedy.text, greedy.logprob)
        assert (fresh[1], fresh[2]) == (drawn, scores)


@pytest.mark.slow  # a second model load, under llama.cpp's grammar sampler (seconds an answer)
def test_llguidance_and_llama_cpp_masks_choose_the_same_tokens(embedded_model_path,
                                                               llama_backend, paper_split):
    """Tests that the fast mask is exact: greedy decoding under llama.cpp's own grammar
    sampler gives the same answers."""
    from ara.eval.translate.backends.llama_cpp_backend import LlamaCppBackend

    builtin = LlamaCppBackend(embedded_model_path, n_ctx=4096, mask="llama")
    shots = sample_shots(paper_split.records("train", "grounded"), 3, random.Random(2))
    for record in paper_split.records("test", "grounded")[:4]:
        prompt = build_prompt(record.nl, record.aps, shots)
        grammar = decoding_grammar(record.aps)
        fast = llama_backend.complete(prompt, grammar, 200, STOP)
        slow = builtin.complete(prompt, grammar, 200, STOP)
        assert fast.text == slow.text, (fast.text, slow.text)


def test_context_overflow_is_refused(llama_backend):
    """Tests the message when prompt plus budget exceed the context."""
    with pytest.raises(BackendError, match="exceeds the context"):
        llama_backend.complete("word " * 5000, None, 16, STOP)


ANSWERS = (" G(!door) & F(goal)\n", " F(goal) & G(!door)\n", " G(door)\n", " G(!door) & F(door)\n")


def test_scores_do_not_depend_on_what_else_is_scored(llama_backend):
    """Tests that answers scored together get exactly what each gets alone, in any
    order: log-probabilities, so below zero."""
    prompt = build_prompt("always avoid the door and eventually reach the goal",
                          ("door", "goal"), ())
    together = llama_backend.score(prompt, ANSWERS)
    assert together == llama_backend.score(prompt, ANSWERS[::-1])[::-1]
    alone = [llama_backend.score(prompt, [a])[0] for a in ANSWERS]
    assert together == alone
    assert all(x < 0 for x in together)
    assert llama_backend.score(prompt, []) == []


@pytest.mark.slow  # two more model loads for a setting
def test_the_thread_count_comes_from_the_caller_or_ara_threads(embedded_model_path,
                                                               monkeypatch):
    """Tests that ARA_THREADS sets llama.cpp's thread count (one thread is what to give a
    model beside another busy process), and that a caller can pass its own."""
    from ara.eval.translate.backends.llama_cpp_backend import LlamaCppBackend

    monkeypatch.setenv("ARA_THREADS", "1")
    assert LlamaCppBackend(embedded_model_path).llm.context_params.n_threads == 1
    monkeypatch.delenv("ARA_THREADS")
    assert LlamaCppBackend(embedded_model_path, n_threads=3).llm.context_params.n_threads == 3
