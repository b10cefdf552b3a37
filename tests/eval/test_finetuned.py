"""The shipped fine-tune: what `--model finetuned` gives a user out of the box."""

import json

import pytest

from ara.eval.models import FINETUNED_LORA, make_backend


@pytest.fixture(scope="module")
def finetuned(embedded_model_path):
    if not FINETUNED_LORA.is_file():
        pytest.skip(f"no shipped adapter at {FINETUNED_LORA} (scripts/finetune_270m.sh)")
    return make_backend("finetuned")


def test_the_adapter_is_the_one_its_manifest_describes():
    if not FINETUNED_LORA.is_file():
        pytest.skip(f"no shipped adapter at {FINETUNED_LORA}")
    from ara.provenance import sha256_file

    manifest = json.loads(FINETUNED_LORA.with_suffix(".json").read_text())
    assert manifest["sha256"] == sha256_file(FINETUNED_LORA)
    assert manifest["run"]["data"]["version"] == "1de1d813ead6"  # the registered paper split
    assert manifest["export"]["parity"]["agreement"] == 1.0


def test_finetuned_translates_test_pairs_the_base_model_gets_wrong(finetuned, llama_backend,
                                                                   paper_split):
    """Zero-shot, grammar-constrained, on 12 grounded test pairs of the paper split: the
    fine-tune's answers are Spot-equivalent to the references, the base model's are not."""
    from ara.eval.harness import judge
    from ara.eval.translator import Translator

    pairs = paper_split.records("test", "grounded")[:12]

    def correct(backend):
        t = Translator(backend)
        return sum(bool(judge(r.stl, t.translate(r.nl, r.aps).stl, timeout_s=10)["equivalent"])
                   for r in pairs)

    tuned, base = correct(finetuned), correct(llama_backend)
    assert tuned >= 11 and base <= 6, (tuned, base)


def test_finetuned_also_translates_with_worked_examples(finetuned, paper_split):
    """With 5 worked examples in the prompt (variant F+C), as with none: the adapter
    trained on a mix of 0- to 20-shot prompts, so examples do not derail it."""
    import random

    from ara.eval.harness import judge
    from ara.eval.prompt import sample_shots
    from ara.eval.translator import Translator

    shots = sample_shots(paper_split.records("train", "grounded"), 5, random.Random(0))
    pairs = paper_split.records("test", "grounded")[12:24]
    t = Translator(finetuned)
    right = sum(bool(judge(r.stl, t.translate(r.nl, r.aps, shots).stl, timeout_s=10)["equivalent"])
                for r in pairs)
    assert right >= 11, right


def test_lora_names_any_adapter_for_the_embedded_base(finetuned, tmp_path):
    """Tests ``--model lora:PATH``: the shipped adapter by path is the ``finetuned``
    model, and a missing file says how to make one."""
    from ara.eval.backends.base import BackendError

    assert make_backend(f"lora:{FINETUNED_LORA}").model_id == finetuned.model_id
    with pytest.raises(BackendError, match="ara export --lora-gguf"):
        make_backend(f"lora:{tmp_path / 'missing.gguf'}")
