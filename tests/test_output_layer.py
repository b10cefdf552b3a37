"""The output layer fed 2-D rows: the same logits as the model's own call, on a tiny Gemma 3."""

import pytest
import torch

from ara.output_layer import output_rows


@pytest.fixture(scope="module")
def tiny_model(tiny_gemma_dir):
    from transformers import AutoModelForCausalLM

    return AutoModelForCausalLM.from_pretrained(tiny_gemma_dir).eval()


@pytest.mark.parametrize("dtype", [torch.float32, torch.bfloat16])
def test_picked_rows_score_as_the_full_call(tiny_model, dtype):
    """Tests that the rows a caller picks get the logits the whole call gives them there,
    in fp32 and in bf16 (where the 3-D product takes another kernel)."""
    model = tiny_model.to(dtype)
    ids = torch.tensor([[2, 818, 5279, 529, 506, 9405]])
    with torch.inference_mode():
        full = model(input_ids=ids).logits[0]
        with output_rows(model, lambda h: h[0, -1:]):
            last = model(input_ids=ids).logits
        with output_rows(model, lambda h: h[0, [1, 3]]):
            some = model(input_ids=ids).logits
    assert last.shape == (1, full.shape[-1]) and some.shape == (2, full.shape[-1])
    tolerance = 1e-5 if dtype == torch.float32 else 2e-2
    torch.testing.assert_close(last[0], full[-1], atol=tolerance, rtol=tolerance)
    torch.testing.assert_close(some, full[[1, 3]], atol=tolerance, rtol=tolerance)


def test_the_layer_is_itself_again_after_an_error(tiny_model):
    """Tests that a failed call leaves no hook behind: the next call scores every position."""
    model = tiny_model.float()
    ids = torch.tensor([[2, 818, 5279]])
    with pytest.raises(IndexError), torch.inference_mode(), output_rows(model, lambda h: h[5]):
        model(input_ids=ids)
    with torch.inference_mode():
        assert model(input_ids=ids).logits.shape[:2] == (1, 3)
