"""A causal LM's output layer run only at the positions a caller needs, on 2-D inputs.

Gemma's output layer (262k words x hidden) costs more than the rest of a 270M model.
Given the usual ``(batch, tokens, hidden)`` input, its product is a batched one, which
in bf16 on a CPU first copies the whole transposed layer (``bench/hf_generation_head.py``
measures what that costs; docs/benchmarks.md).
Training and the transformers backend both hand it the two-dimensional rows they need,
each with its own ``pick``, while the model's own forward still runs (so wrappers such
as peft and DDP see the call).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any


@contextmanager
def output_rows(model: Any, pick: Callable[[Any], Any]) -> Iterator[None]:
    """While open, the output layer gets ``pick(hidden)`` in place of its input.

    ``pick`` maps the ``(batch, kept, hidden)`` states the model feeds its output layer
    (after its own ``logits_to_keep`` slice, when given one) to the 2-D
    ``(rows, hidden)`` it should score; the forward's ``logits`` are then
    ``(rows, vocab)``.

    >>> with output_rows(model, lambda h: h[0, -1:]):  # the last position alone
    ...     next_token_logits = model(input_ids=ids).logits[0]
    """
    head = getattr(model, "module", model).get_output_embeddings()
    hook = head.register_forward_pre_hook(lambda _, args: (pick(args[0]), *args[1:]))
    try:
        yield
    finally:
        hook.remove()
