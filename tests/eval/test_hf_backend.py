"""The transformers backend on the embedded model converted to a HF folder."""

import random

import pytest

from ara.eval.translate.backends.base import BackendError
from ara.eval.translate.prompt import STOP, build_prompt, sample_shots
from ara.eval.translate.translator import Translator


@pytest.mark.slow  # test_decoding_sums_the_log_probability_scoring_gives decodes under the grammar
def test_constrained_outputs_belong_to_the_language(hf_backend, paper_split):
    """Tests the guarantee through transformers + llguidance on real generations."""
    translator = Translator(hf_backend)
    rng = random.Random(3)
    shots = sample_shots(paper_split.records("train", "grounded"), 3, rng)
    for record in rng.sample(paper_split.records("test", "grounded"), 3):
        result = translator.translate(record.nl, record.aps, shots)
        assert result.valid and translator.config.syntax(record.aps).accepts(result.stl), result


@pytest.mark.slow  # loads a second model, as llama.cpp's prefix-reuse test (slow too) does
def test_prefix_reuse_gives_the_fresh_answer(hf_backend, hf_model_dir, paper_split):
    """Tests that cropping the cache to the shared prefix changes no answer."""
    from ara.eval.translate.backends.hf_backend import HFBackend

    shots = sample_shots(paper_split.records("train", "lifted"), 3, random.Random(4))
    prompts = [build_prompt(r.nl, r.aps, shots) for r in paper_split.records("test", "lifted")[:2]]
    warm = [hf_backend.complete(p, None, 24, STOP) for p in prompts]
    assert warm[1].cached_tokens > 0.8 * warm[1].prompt_tokens
    fresh = HFBackend(hf_model_dir).complete(prompts[1], None, 24, STOP)
    assert fresh.text == warm[1].text


@pytest.mark.slow  # outlines' CFG path takes over a minute for two answers on 2 cores
def test_outlines_and_llguidance_paths_agree(hf_backend, hf_model_dir, paper_split):
    """Tests that outlines' CFG generation and our masked greedy loop give the same answer."""
    from ara.eval.translate.backends.hf_backend import HFBackend

    via_outlines = Translator(HFBackend(hf_model_dir, mask="outlines"))
    via_loop = Translator(hf_backend)
    shots = sample_shots(paper_split.records("train", "lifted"), 3, random.Random(5))
    for record in paper_split.records("test", "lifted")[:2]:
        a = via_outlines.translate(record.nl, record.aps, shots)
        b = via_loop.translate(record.nl, record.aps, shots)
        assert a.valid and a.stl == b.stl


@pytest.mark.slow  # outlines' CFG path takes over a minute for two answers on 2 cores
def test_repair_on_a_backend_that_cannot_sample_ranks_what_it_has(hf_model_dir, paper_split):
    """Tests that outlines' greedy-only masks make repair draw nothing, not fail: every
    greedy answer is doubted here (doubt 1), which would draw 8 samples."""
    from ara.eval.translate.backends.hf_backend import HFBackend
    from ara.eval.translate.repair import RepairConfig, translate_repaired

    translator = Translator(HFBackend(hf_model_dir, mask="outlines"))
    assert not translator.backend.can_sample and translator.can_score
    record = paper_split.records("test", "lifted")[0]
    vote = translate_repaired(translator, record.nl, record.aps,
                              repair=RepairConfig(8, doubt=1.0))
    assert vote.answers and all(a is not None for a in vote.answers)


def test_unknown_model_is_a_clear_error(tmp_path):
    """Tests the message for a folder that holds no model (nothing is downloaded)."""
    from ara.eval.translate.backends.hf_backend import HFBackend

    with pytest.raises(BackendError, match="cannot load"):
        HFBackend(str(tmp_path / "nothing-here"))


def test_transformers_and_llama_cpp_score_answers_alike(hf_backend, llama_backend):
    """Tests one model's two runtimes against each other: the same answers get nearly
    the same log-probability (the HF folder is the GGUF's weights, dequantized)."""
    prompt = build_prompt("always avoid the door and eventually reach the goal",
                          ("door", "goal"), ())
    answers = [" G(!door) & F(goal)\n", " F(goal) & G(!door)\n", " G(door)\n",
               " G(!door) & F(door)\n"]
    assert hf_backend.score(prompt, answers) == pytest.approx(
        llama_backend.score(prompt, answers), abs=1.5)


def test_decoding_sums_the_log_probability_scoring_gives(hf_backend, llama_backend):
    """Tests that a completion decoded under the grammar is in the language, and that
    its log-probability, summed while decoding, is what scoring its text gives, in both
    runtimes (the free check `ara translate` runs on every answer)."""
    from ara.data import load_or_prepare
    from ara.eval.translate.translator import decoding_grammar

    # Worked examples keep the base model to tokens it would choose unmasked: where the
    # mask overrules it, it may write a formula in tokens not the tokenizer's own
    shots = sample_shots(load_or_prepare("compositional").records("train", "lifted"), 5,
                         random.Random(0))
    nl, aps = "always avoid the door and eventually reach the goal", ("door", "goal")
    prompt = build_prompt(nl, aps, shots)
    for backend in (hf_backend, llama_backend):
        grammar = decoding_grammar(Translator(backend).grammar(aps, nl))
        completion = backend.complete(prompt, grammar, 64, STOP)
        assert Translator(backend).grammar(aps, nl).syntax.accepts(completion.text.strip())
        assert completion.logprob is not None, completion.text  # the tokenizer's own tokens
        assert completion.logprob == pytest.approx(backend.score(prompt, [completion.text])[0],
                                                   abs=0.5)


@pytest.mark.slow  # loads a second model to score afresh
def test_scores_shared_prefixes_change_only_float_rounding(hf_backend, hf_model_dir):
    """Tests that the transformers backend, which feeds answers after the prefix they
    share with the one before, scores each as a fresh model scoring it alone does, up
    to float32 rounding (llama.cpp's kernels differed by up to 0.9 in a logit, so that
    backend scores each answer alone; this one need not)."""
    from ara.eval.translate.backends.hf_backend import HFBackend

    prompt = build_prompt("always avoid the door and eventually reach the goal",
                          ("door", "goal"), ())
    answers = [" G(!door) & F(goal)\n", " G(!door) & F(door)\n", " G(door)\n",
               " F(goal) & G(!door)\n"]
    together = hf_backend.score(prompt, answers)
    fresh = HFBackend(hf_model_dir)
    alone = [fresh.score(prompt, [a])[0] for a in answers]
    assert together == pytest.approx(alone, abs=1e-4)
    assert all(x < -1 for x in together)
