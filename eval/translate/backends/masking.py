"""Grammar-constrained token choice with llguidance, shared by the local backends.

Greedy decoding under a grammar needs the best *allowed* token. Computing the full
allowed-token mask over Gemma's 262k vocabulary, and applying it to the logits in
numpy, is the dear part of a step, and most steps need neither
(bench/constrained_overhead.py measures it). Sample-then-check:
take the unconstrained argmax, ask the matcher whether it may follow; only when it
may not, compute the mask and take the argmax over the allowed tokens. The result is
exactly the masked greedy choice either way.

The local backends also share their decoding loop (:func:`greedy_decode`) and the
teacher-forced scoring of whole answers (:func:`score_paths`) from here.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from functools import lru_cache

import numpy as np

from ara.eval.translate.backends.base import Sampling
from ara.grammars import BuiltGrammar


class GrammarMatcher:
    """One generation's grammar state.

    Args:
        tokenizer: An ``llguidance.LLTokenizer`` for the model's vocabulary.
        grammar: The grammar to follow (its Lark text is compiled by llguidance).
    """

    def __init__(self, tokenizer, grammar: BuiltGrammar) -> None:
        self._matcher = _compiled(tokenizer, grammar.grammar.to_lark()).deep_copy()
        self._n_words = (tokenizer.vocab_size + 31) // 32
        self._mask = np.zeros(self._n_words, dtype=np.int32)
        self.masked_steps = 0

    def choose(self, logits: np.ndarray, sampler: Sampler | None = None) -> int:
        """The highest-scoring token the grammar allows next (or one drawn from the
        allowed tokens' distribution, with ``sampler``), and consume it."""
        if sampler is None:
            token = int(np.argmax(logits))
            if token < self._n_words * 32 and self._matcher.try_consume_tokens([token]) == 1:
                return token
        self.masked_steps += 1
        self._matcher.unsafe_compute_mask_ptr(self._mask.ctypes.data, self._mask.nbytes)
        allowed = allowed_tokens(self._mask, len(logits))
        if allowed.size == 0:
            raise RuntimeError(f"grammar allows no token: {self._matcher.get_error()}")
        scores = logits[allowed]
        token = int(allowed[np.argmax(scores) if sampler is None else sampler(scores)])
        if not self._matcher.consume_token(token):
            raise RuntimeError(f"llguidance refused its own mask: {self._matcher.get_error()}")
        return token


class Sampler:
    """Draws a token index from ``softmax(scores / temperature)``, seeded.

    Sampling from the allowed tokens' renormalized distribution is sampling from the
    model conditioned on the grammar, one step at a time.
    """

    def __init__(self, sampling: Sampling) -> None:
        self.temperature = sampling.temperature
        self.rng = np.random.default_rng(sampling.seed)

    def __call__(self, scores: np.ndarray) -> int:
        z = (scores.astype(np.float64) - scores.max()) / self.temperature
        p = np.exp(z)
        return int(self.rng.choice(len(p), p=p / p.sum()))


def greedy_decode(logits: np.ndarray, advance: Callable[[int], np.ndarray],
                  detokenize: Callable[[list[int]], str], matcher: GrammarMatcher | None,
                  eos: set[int], max_tokens: int, stop: str,
                  sampler: Sampler | None = None) -> tuple[str, list[int], str, float]:
    """The decoding loop both local backends share: greedy, or sampled with ``sampler``.

    Args:
        logits: Scores after the prompt.
        advance: Feeds one chosen token to the model, returns the next scores.
        detokenize: Token ids to text.
        matcher: The grammar's state, or ``None`` to decode freely until ``stop``.
        eos: Tokens that end generation (the grammar allows them once it is complete).
        max_tokens: Token budget.
        stop: Free decoding ends at this string, which is not returned.
        sampler: Draw each token instead of taking the argmax.

    Returns:
        ``(text, tokens, reason, logprob)`` with reason ``eos``, ``stop`` or ``length``,
        and ``logprob`` the model's log-probability of ``tokens`` from the scores before
        any mask: what :func:`score_paths` gives the same tokens, without a second pass
        (the end-of-text token is not counted, as scoring does not feed it).
    """
    out: list[int] = []
    text = ""
    logprob = 0.0
    for _ in range(max_tokens):
        if matcher is not None:
            token = matcher.choose(logits, sampler)
        else:
            token = int(np.argmax(logits)) if sampler is None else sampler(logits)
        if token in eos:
            return text, out, "eos", logprob
        out.append(token)
        logprob += _log_softmax_at(logits, token)
        text = detokenize(out)
        if matcher is None and stop in text:
            return text[: text.index(stop)], out, "stop", logprob
        logits = advance(token)
    return text, out, "length", logprob


def _log_softmax_at(row: np.ndarray, token: int) -> float:
    """``log_softmax(row)[token]``, in float64."""
    row = row.astype(np.float64)
    top = row.max()
    return float(row[token] - top - np.log(np.exp(row - top).sum()))


def score_paths(prompt: Sequence[int], paths: Sequence[Sequence[int]],
                rows: Callable[[int, list[int]], np.ndarray]) -> list[float]:
    """Log-probability of each token path after ``prompt``, teacher-forced.

    Paths go in sorted order, so each shares the longest prefix it can with the one
    before it: that prefix's log-probabilities are kept, and only the rest is fed, in
    one batch.

    Args:
        prompt: The prompt's token ids (at least one).
        paths: Token ids of each continuation.
        rows: ``rows(start, tokens)`` rolls the model back to its first ``start``
            tokens of ``prompt + path``, feeds ``tokens`` from there, and returns the
            scores after each of them (one row per token).
    """
    totals = [0.0] * len(paths)
    done: list[int] = []
    done_logp: list[float] = []
    for i in sorted(range(len(paths)), key=lambda i: list(paths[i])):
        path = list(paths[i])
        shared = next((k for k, (a, b) in enumerate(zip(path, done, strict=False)) if a != b),
                      min(len(path), len(done)))
        logp = done_logp[:shared]
        if shared < len(path):
            # The scores for token ``shared`` come after feeding the one before it.
            start = len(prompt) + shared - 1
            feed = [*prompt, *path][start: len(prompt) + len(path) - 1]
            for row, token in zip(rows(start, feed), path[shared:], strict=True):
                logp.append(_log_softmax_at(row, token))
        totals[i] = sum(logp)
        done, done_logp = path, logp
    return totals


@lru_cache(maxsize=256)
def _compiled(tokenizer, lark_text: str):
    """A pristine matcher per grammar; each generation works on a deep copy of it."""
    import llguidance

    matcher = llguidance.LLMatcher(tokenizer, llguidance.LLMatcher.grammar_from_lark(lark_text))
    if matcher.is_error():
        raise ValueError(f"llguidance rejected the grammar: {matcher.get_error()}")
    return matcher


def allowed_tokens(mask: np.ndarray, vocab_size: int) -> np.ndarray:
    """Token ids whose bit is set in an llguidance bitmask (32 tokens per int32 word).

    Only the non-zero words are unpacked: under a grammar, a few dozen of Gemma's
    262k tokens are allowed at a time.
    """
    words = np.flatnonzero(mask)
    bits = ((mask[words, None].astype(np.uint32) >> np.arange(32, dtype=np.uint32)) & 1)
    ids = (words[:, None] * 32 + np.arange(32))[bits.astype(bool)]
    return ids[ids < vocab_size]
