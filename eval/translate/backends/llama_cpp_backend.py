"""llama.cpp through llama-cpp-python: any GGUF, the embedded Gemma 3 270M by default.

Decoding is our own greedy loop over ``Llama.eval`` rather than ``create_completion``,
for two reasons. Constraint: llguidance's mask replaces llama.cpp's built-in grammar
sampler, which checks the whole 262k-token vocabulary at every step (slower per
formula, as ``bench/constrained_overhead.py`` measures). The built-in sampler stays
available (``mask="llama"``) for faithfulness to the paper's setup. Prefix reuse: the
longest common token prefix with the previous prompt keeps its KV cache, so a run that
shares its few-shot examples evaluates them once. The cache is full-size
(``swa_full``), because Gemma 3's sliding-window cache cannot roll back to an earlier
position once it has slid past it.

An answer must not depend on what was asked before it. llama.cpp's CPU kernels give a
position's scores a little differently depending on where it falls in the batch that
computed it (a quantized matrix product takes rows four at a time and the leftover
ones another way), enough to change a sampled answer or the ranking of two close ones.
So prompts are fed in chunks that start at fixed positions (multiples of :data:`CHUNK`),
only whole chunks are reused, and asking the same prompt again (the samples of one
request) reuses its scores rather than re-feeding its last token: every position is
computed the way a fresh model computes it, whatever came before.
"""

from __future__ import annotations

import os
import time
import warnings
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ara.eval.translate.backends.base import BackendError, Completion, Sampling
from ara.eval.translate.backends.masking import GrammarMatcher, Sampler, greedy_decode, score_paths
from ara.eval.translate.llama_check import muted_llama_log
from ara.grammars import BuiltGrammar
from ara.provenance import sha256_file

MASK_ENGINES = ("llguidance", "llama")


def lora_id(lora_path: str | Path) -> str:
    """What a LoRA adds to a run's ``model_id``: its file's hash, so a run's record names
    the very adapter that answered."""
    return f"+lora:sha256:{sha256_file(lora_path)[:16]}"

#: Prompt positions are fed in chunks starting at multiples of this; whole chunks are
#: the unit of reuse. Larger reuses less of a shared prefix, smaller feeds more batches.
CHUNK = 64


class LlamaCppBackend:
    """A GGUF model run by llama.cpp on the CPU (or GPU layers if built for it).

    Args:
        model_path: Path to a ``.gguf`` file.
        n_ctx: Context length in tokens; 20-shot prompts need about 1,500.
        n_threads: CPU threads; default ``$ARA_THREADS``, else all cores. Beside another
            busy process, one thread is far faster than two: llama.cpp's threads wait on
            each other at every layer, and one of them is always waiting for a core.
        mask: ``llguidance`` (fast masks, default) or ``llama`` (llama.cpp's own
            grammar sampler on the GBNF text).
        lora_path: Optional GGUF LoRA adapter applied on top of the model.

    Raises:
        BackendError: If the model file is missing or llama.cpp cannot load it.
    """

    can_sample = True
    #: One llama.cpp context decodes one sequence at a time.
    concurrent = False

    def __init__(self, model_path: str, n_ctx: int = 4096, n_threads: int | None = None,
                 mask: str = "llguidance", lora_path: str | None = None) -> None:
        import llama_cpp

        if mask not in MASK_ENGINES:
            raise BackendError(f"unknown mask engine {mask!r}; choose one of {MASK_ENGINES}")
        for path in filter(None, (model_path, lora_path)):
            if not Path(path).is_file():
                raise BackendError(f"model file not found: {path}")
        self._lc = llama_cpp
        try:
            with muted_llama_log():
                self.llm = llama_cpp.Llama(
                    model_path=str(model_path), n_ctx=n_ctx,
                    n_threads=n_threads or int(os.environ.get("ARA_THREADS") or 0)
                    or os.cpu_count(), swa_full=True, verbose=False,
                    lora_path=lora_path,
                )
        except ValueError as err:
            raise BackendError(f"llama.cpp could not load {model_path}: {err}") from err
        self.mask = mask
        self.model_id = f"gguf:{Path(model_path).name}:sha256:{sha256_file(model_path)[:16]}"
        if lora_path:
            self.model_id += lora_id(lora_path)
        self._vocab = llama_cpp.llama_model_get_vocab(self.llm._model.model)
        self._eos = {self.llm.token_eos(), *self._end_of_turn()}
        self._lltokenizer = None
        # The last prompt fed, its scores, and how many of its leading positions the
        # cache still holds as that feed computed them (scoring may overwrite the last).
        self._prompt: list[int] = []
        self._prompt_logits: np.ndarray | None = None
        self._intact = 0

    def _end_of_turn(self) -> list[int]:
        ids = self.llm.tokenize(b"<end_of_turn>", add_bos=False, special=True)
        return ids if len(ids) == 1 else []

    @property
    def lltokenizer(self):
        """llguidance's view of the vocabulary (built once, ~1 s for 262k tokens)."""
        if self._lltokenizer is None:
            from llguidance.llamacpp import lltokenizer_from_vocab

            # llguidance reads each token's attributes through a function llama-cpp-python
            # has deprecated: 262k identical warnings, nothing for us to act on.
            with warnings.catch_warnings():
                warnings.filterwarnings("ignore", "llama_token_get_attr", DeprecationWarning)
                self._lltokenizer = lltokenizer_from_vocab(self._vocab,
                                                           eos_token=sorted(self._eos))
        return self._lltokenizer

    def _logits(self) -> np.ndarray:
        return np.ctypeslib.as_array(self.llm._ctx.get_logits(), shape=(self.llm.n_vocab(),))

    def _feed_prompt(self, tokens: list[int]) -> tuple[np.ndarray, int]:
        """Evaluate the prompt as a fresh model would, reusing what the cache holds of it
        (module docstring); returns the scores after its last token (a copy) and how
        many positions were reused."""
        if tokens == self._prompt and self._intact == len(tokens):
            self.llm.n_tokens = len(tokens)  # generated positions are dropped on next eval
            return self._prompt_logits.copy(), len(tokens)
        cached = self._prompt[: self._intact]
        limit = min(len(cached), len(tokens) - 1)  # evaluate >= 1 token to get logits
        same = np.flatnonzero(np.asarray(cached[:limit]) != np.asarray(tokens[:limit]))
        shared = int(same[0]) if same.size else limit
        reused = shared // CHUNK * CHUNK  # shared <= _intact: cached is that long
        self.llm.n_tokens = reused
        for begin in range(reused, len(tokens), CHUNK):
            self.llm.eval(tokens[begin: begin + CHUNK])
        self._prompt, self._intact = list(tokens), len(tokens)
        self._prompt_logits = self._logits().copy()
        return self._prompt_logits.copy(), reused

    def complete(self, prompt: str, grammar: BuiltGrammar | None, max_tokens: int,
                 stop: str, sampling: Sampling | None = None) -> Completion:
        if grammar is not None and self.mask == "llguidance":
            self.lltokenizer  # noqa: B018 - built once, outside the timed call
        start = time.perf_counter()
        tokens = self.llm.tokenize(prompt.encode(), add_bos=True, special=False)
        if len(tokens) + max_tokens > self.llm.n_ctx():
            raise BackendError(
                f"prompt of {len(tokens)} tokens + {max_tokens} to generate exceeds the "
                f"context of {self.llm.n_ctx()}; pass a larger n_ctx or fewer shots"
            )
        first, reused = self._feed_prompt(tokens)
        if grammar is not None and self.mask == "llama":
            if sampling is not None:
                raise BackendError("sampling runs with the llguidance mask; pass mask='llguidance'")
            return self._complete_llama_grammar(grammar, max_tokens, len(tokens), reused, start)
        matcher = GrammarMatcher(self.lltokenizer, grammar) if grammar is not None else None

        def advance(token: int) -> np.ndarray:
            self.llm.eval([token])
            return self._logits()

        text, out, reason, logprob = greedy_decode(
            first, advance,
            lambda ids: self.llm.detokenize(ids).decode("utf-8", errors="replace"),
            matcher, self._eos, max_tokens, stop, Sampler(sampling) if sampling else None)
        return Completion(text, len(tokens), len(out), reused,
                          (time.perf_counter() - start) * 1e3, reason,
                          matcher.masked_steps if matcher else 0,
                          logprob if self._is_own_tokenization(text, out) else None)

    def _is_own_tokenization(self, text: str, tokens: list[int]) -> bool:
        """Whether ``tokens`` are how the tokenizer writes ``text``, so that their
        log-probability is the one scoring ``text`` gives."""
        return self.llm.tokenize(text.encode(), add_bos=False, special=False) == tokens

    def score(self, prompt: str, continuations: Sequence[str]) -> list[float]:
        """Log-probability of each continuation after ``prompt``, teacher-forced without a
        grammar (see :func:`~ara.eval.translate.backends.masking.score_paths`); each the same
        whatever else is scored with it."""
        tokens = self.llm.tokenize(prompt.encode(), add_bos=True, special=False)
        paths = [self.llm.tokenize(c.encode(), add_bos=False, special=False)
                 for c in continuations]
        longest = max(map(len, paths), default=0)
        if len(tokens) + longest > self.llm.n_ctx() or longest > self.llm.n_batch:
            raise BackendError(f"prompt of {len(tokens)} tokens + {longest} to score exceeds "
                               f"the context of {self.llm.n_ctx()} or a batch of "
                               f"{self.llm.n_batch}")
        first, _ = self._feed_prompt(tokens)

        def rows(start: int, fed: list[int]) -> np.ndarray:
            if start == len(tokens) - 1:  # the prompt's last position: its scores, kept
                head = first[None, :]
                return head if len(fed) == 1 else np.vstack([head, self._rows(start + 1,
                                                                               fed[1:])])
            return self._rows(start, fed)

        # One path at a time, each fed from the prompt's end: sharing a prefix with the
        # path before it would make a path's score depend on what else is scored.
        return [score_paths(tokens, [path], rows)[0] for path in paths]

    def _rows(self, start: int, tokens: list[int]) -> np.ndarray:
        """Scores after each of ``tokens``, fed at position ``start`` in one batch.

        ``Llama.eval`` keeps only the last position's scores unless the whole context
        was made with ``logits_all`` (a vocabulary-wide row per context position,
        gigabytes here), so this asks llama.cpp for every row of this one batch only.
        """
        llm = self.llm
        self._intact = min(self._intact, start)
        llm.n_tokens = start
        llm._ctx.kv_cache_seq_rm(-1, start, -1)
        llm._batch.set_batch(batch=tokens, n_past=start, logits_all=True)
        llm._ctx.decode(llm._batch)
        llm.input_ids[start: start + len(tokens)] = tokens
        llm.n_tokens = start + len(tokens)
        return np.ctypeslib.as_array(llm._ctx.get_logits(),
                                     shape=(len(tokens), llm.n_vocab())).copy()

    def _complete_llama_grammar(self, grammar: BuiltGrammar, max_tokens: int, n_prompt: int,
                                reused: int, start: float) -> Completion:
        """Greedy decoding through llama-cpp-python's own grammar sampling (the paper's
        path): llama.cpp checks every vocabulary entry against the GBNF at each step."""
        gbnf = self._lc.LlamaGrammar.from_string(grammar.grammar.to_gbnf(), verbose=False)
        prompt_tokens = self.llm.input_ids[: self.llm.n_tokens].tolist()
        self._intact = min(self._intact, n_prompt - 1)  # llama-cpp-python re-feeds the last
        result = self.llm.create_completion(prompt_tokens, max_tokens=max_tokens, temperature=0.0,
                                            grammar=gbnf)
        choice = result["choices"][0]
        reason = "eos" if choice["finish_reason"] == "stop" else "length"
        return Completion(choice["text"], n_prompt, result["usage"]["completion_tokens"], reused,
                          (time.perf_counter() - start) * 1e3, reason)
