"""What every translation backend provides: a completion of one prompt.

A backend turns ``(prompt, grammar or None, max_tokens)`` into a :class:`Completion`.
With a grammar, the backend guarantees that the returned text is a complete string of
that grammar, or says it could not (``stop == "length"``); :mod:`ara.eval.translate.translator`
turns completions into parsed formulas.

The local backends can also score answers: ``score(prompt, continuations)``, the
log-probability of each continuation after the prompt (what repair ranks answers by,
:mod:`ara.eval.translate.repair`). It is not part of :class:`Backend`, since an HTTP server
gives no such call; callers check for it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

from ara.errors import AraError
from ara.grammars import BuiltGrammar


class BackendError(AraError, RuntimeError):
    """A backend that cannot run: missing model file, unreachable endpoint, ..."""


@dataclass(frozen=True)
class Completion:
    """One generated answer.

    Attributes:
        text: The generated text, without the stop string.
        prompt_tokens: Tokens in the prompt.
        completion_tokens: Tokens generated.
        cached_tokens: Prompt tokens whose KV cache was reused from the previous call.
        ms: Wall time of the call in milliseconds.
        stop: ``eos`` (model or grammar ended it), ``stop`` (stop string), ``length``
            (token budget spent).
        masked_steps: Steps at which the model's first choice broke the grammar and the
            mask was computed (constrained decoding only).
        logprob: The model's log-probability of ``text`` (scores before any mask), where
            the tokens generated are the tokenizer's own for ``text``; else ``None``, as
            from a server.
    """

    text: str
    prompt_tokens: int
    completion_tokens: int
    cached_tokens: int
    ms: float
    stop: str
    masked_steps: int = 0
    logprob: float | None = None


@dataclass(frozen=True)
class Sampling:
    """Draw tokens from the model's distribution instead of taking the best one.

    Args:
        temperature: Softmax temperature, > 0 (lower is closer to greedy).
        seed: Seeds the draws, so one (prompt, seed) gives one answer.
    """

    temperature: float = 0.7
    seed: int = 0

    def __post_init__(self) -> None:
        if not self.temperature > 0:
            raise BackendError(f"sampling temperature must be > 0, got {self.temperature}; "
                               "for greedy decoding pass no Sampling")


class Backend(Protocol):
    """A model that completes prompts, optionally under a grammar."""

    #: Identifies the model in outputs (file hash, hub id or endpoint and model name).
    model_id: str
    #: ``complete`` takes a :class:`Sampling` (repair draws answers); else it keeps the
    #: greedy one.
    can_sample: bool
    #: ``complete`` may be called from several threads at once (``--concurrency``).
    concurrent: bool

    def complete(self, prompt: str, grammar: BuiltGrammar | None, max_tokens: int,
                 stop: str, sampling: Sampling | None = None) -> Completion:
        """Completion of ``prompt``: greedy, or sampled with ``sampling``.

        Args:
            prompt: The full prompt.
            grammar: Constrain the answer to this grammar's language, or ``None``.
            max_tokens: Token budget for the answer.
            stop: Unconstrained generation ends at this string (not returned).
            sampling: Draw tokens (seeded) instead of taking the argmax; backends that
                cannot raise :class:`BackendError`.
        """
        ...
