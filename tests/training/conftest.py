"""The tiny Gemma 3 the training tests share: built once per session, not per module."""

import pytest


@pytest.fixture(scope="session")
def tiny_gemma_dir(tmp_path_factory, hf_model_dir):
    """A 2-layer, 32-wide Gemma 3 with random weights and the real 262k tokenizer."""
    from ara.training.tiny import build_tiny_gemma

    return build_tiny_gemma(tmp_path_factory.mktemp("tiny-gemma"), hf_model_dir)
