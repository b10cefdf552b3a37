"""A Hugging Face transformers model, constrained through llguidance or outlines.

``mask="llguidance"`` (default) runs our own greedy loop: the KV cache of the longest
common prefix with the previous prompt is kept (``DynamicCache.crop``), and the
grammar is applied with sample-then-check exactly as in the llama.cpp backend.
``mask="outlines"`` hands each call to ``outlines.Generator`` with a ``CFG`` output type,
which is the library path the paper's setup describes. It is kept for faithfulness;
``bench/constrained_overhead.py`` measures its cost.

Models load with ``local_files_only=True``: a local folder (``ara model prepare`` makes
one from the embedded GGUF) or a hub id already in the local cache. Nothing downloads.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ara.eval.translate.backends.base import BackendError, Completion, Sampling
from ara.eval.translate.backends.masking import GrammarMatcher, Sampler, greedy_decode, score_paths
from ara.grammars import BuiltGrammar
from ara.kv_cache import cache_of, with_cache
from ara.output_layer import output_rows

MASK_ENGINES = ("llguidance", "outlines")


class HFBackend:
    """Greedy completions from a transformers causal LM.

    Args:
        model: Local folder or cached hub id.
        mask: ``llguidance`` or ``outlines``.
        device: ``cpu``, ``cuda``, ... (default: cuda if available).
        dtype: torch dtype name for the weights (default float32 on CPU, bfloat16 on GPU).
    """

    #: One model decodes one prompt at a time (batched decoding is not written).
    concurrent = False

    def __init__(self, model: str, mask: str = "llguidance", device: str | None = None,
                 dtype: str | None = None) -> None:
        import torch
        from transformers import AutoModelForCausalLM, AutoTokenizer

        if mask not in MASK_ENGINES:
            raise BackendError(f"unknown mask engine {mask!r}; choose one of {MASK_ENGINES}")
        self._torch = torch
        self.can_sample = mask == "llguidance"  # outlines' masks are for greedy decoding
        self.device = device or ("cuda" if torch.cuda.is_available() else "cpu")
        dtype = dtype or ("float32" if self.device == "cpu" else "bfloat16")
        try:
            self.tokenizer = AutoTokenizer.from_pretrained(model, local_files_only=True)
            self.model = AutoModelForCausalLM.from_pretrained(
                model, local_files_only=True, dtype=getattr(torch, dtype)).to(self.device)
        except OSError as err:
            raise BackendError(
                f"cannot load {model!r} locally ({err.__class__.__name__}); give a folder "
                "(`ara model prepare` converts the embedded model) or a hub id already cached"
            ) from err
        self._init_state(mask, f"hf:{Path(model).name}")

    @classmethod
    def from_objects(cls, model, tokenizer, model_id: str, mask: str = "llguidance") -> HFBackend:
        """A backend around a model already in memory (e.g. a PEFT model being trained)."""
        import torch

        self = cls.__new__(cls)
        self.model, self.tokenizer = model, tokenizer
        self.device = next(model.parameters()).device.type
        self._torch = torch
        self._init_state(mask, model_id)
        return self

    def _init_state(self, mask: str, model_id: str) -> None:
        self.model.eval()
        self.mask = mask
        self.model_id = model_id
        eos = self.model.generation_config.eos_token_id
        self._eos = set(eos if isinstance(eos, list) else [eos]) | {self.tokenizer.eos_token_id}
        self._eos.discard(None)
        self._cache = None
        self._cached_ids: list[int] = []
        self._lltokenizer = None
        self._outlines = None

    @property
    def lltokenizer(self):
        if self._lltokenizer is None:
            import llguidance.hf

            self._lltokenizer = llguidance.hf.from_tokenizer(self.tokenizer,
                                                             eos_token=sorted(self._eos))
        return self._lltokenizer

    def _forward(self, ids: list[int]) -> np.ndarray:
        """Feed ``ids`` after the cached ones; the last position's logits as float32."""
        torch = self._torch
        # h[0, -1:] and not h[0, -1]: the output layer gets 2-D rows (ara.output_layer).
        with torch.inference_mode(), output_rows(self.model, lambda h: h[0, -1:]):
            out = self.model(input_ids=torch.tensor([ids], device=self.device),
                             use_cache=True, **with_cache(self._cache))
        self._cache = cache_of(out)
        self._cached_ids += ids
        return out.logits[-1].float().cpu().numpy()

    def _feed_prompt(self, ids: list[int]) -> tuple[np.ndarray, int]:
        from transformers import DynamicCache

        limit = min(len(self._cached_ids), len(ids) - 1)
        reused = next((i for i in range(limit) if self._cached_ids[i] != ids[i]), limit)
        if reused and self._cache is not None:
            # crop() takes minus the number of tokens to drop. The cache was made without a
            # config, so every layer keeps all positions (the sliding-window layers too),
            # which is what makes rolling back exact.
            self._cache.crop(reused - len(self._cached_ids))
            self._cached_ids = self._cached_ids[:reused]
        else:
            self._cache, self._cached_ids, reused = DynamicCache(), [], 0
        return self._forward(ids[reused:]), reused

    def complete(self, prompt: str, grammar: BuiltGrammar | None, max_tokens: int,
                 stop: str, sampling: Sampling | None = None) -> Completion:
        if grammar is not None and self.mask == "llguidance":
            self.lltokenizer  # noqa: B018 - built once, outside the timed call
        if grammar is not None and self.mask == "outlines":
            if sampling is not None:
                raise BackendError("sampling runs with the llguidance mask; pass mask='llguidance'")
            return self._complete_outlines(prompt, grammar, max_tokens)
        start = time.perf_counter()
        ids = self.tokenizer(prompt, add_special_tokens=True)["input_ids"]
        logits, reused = self._feed_prompt(ids)
        matcher = GrammarMatcher(self.lltokenizer, grammar) if grammar is not None else None
        text, out, reason, logprob = greedy_decode(
            logits, lambda token: self._forward([token]), self.tokenizer.decode, matcher,
            self._eos, max_tokens, stop, Sampler(sampling) if sampling else None)
        own = self.tokenizer(text, add_special_tokens=False)["input_ids"] == out
        return Completion(text, len(ids), len(out), reused, (time.perf_counter() - start) * 1e3,
                          reason, matcher.masked_steps if matcher else 0,
                          logprob if own else None)

    def score(self, prompt: str, continuations: Sequence[str]) -> list[float]:
        """Log-probability of each continuation after ``prompt``, teacher-forced without a
        grammar (see :func:`~ara.eval.translate.backends.masking.score_paths`)."""
        ids = self.tokenizer(prompt, add_special_tokens=True)["input_ids"]
        paths = [self.tokenizer(c, add_special_tokens=False)["input_ids"] for c in continuations]
        self._feed_prompt(ids)
        return score_paths(ids, paths, self._rows)

    def _rows(self, start: int, tokens: list[int]) -> np.ndarray:
        """Scores after each of ``tokens``, fed after the first ``start`` cached ones."""
        torch = self._torch
        if start < len(self._cached_ids):  # crop(0) would empty the cache
            self._cache.crop(start - len(self._cached_ids))
            self._cached_ids = self._cached_ids[:start]
        with torch.inference_mode(), output_rows(self.model, lambda h: h[0]):
            out = self.model(input_ids=torch.tensor([tokens], device=self.device),
                             use_cache=True, **with_cache(self._cache))
        self._cache = cache_of(out)
        self._cached_ids += tokens
        return out.logits.float().cpu().numpy()

    def _complete_outlines(self, prompt: str, grammar: BuiltGrammar,
                           max_tokens: int) -> Completion:
        import outlines
        from outlines.types import CFG

        if self._outlines is None:
            self._outlines = outlines.from_transformers(self.model, self.tokenizer)
        start = time.perf_counter()
        generator = outlines.Generator(self._outlines, CFG(grammar.grammar.to_lark()))
        text = generator(prompt, max_new_tokens=max_tokens, do_sample=False)
        n_prompt = len(self.tokenizer(prompt)["input_ids"])
        n_out = len(self.tokenizer(text, add_special_tokens=False)["input_ids"])
        return Completion(text, n_prompt, n_out, 0, (time.perf_counter() - start) * 1e3, "eos")
