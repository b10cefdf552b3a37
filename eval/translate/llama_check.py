"""Ask llama.cpp's own grammar engine whether it admits a string under a GBNF grammar.

This is the engine that ``Llama(..., grammar=...)`` decodes with, so agreement here is
agreement with what constrained generation can produce. A string is fed token by
token (tokenized with the model's vocabulary); each token is first offered to the
grammar sampler, which sets the logit of a token it forbids to minus infinity, and
only then accepted, since accepting a forbidden token aborts inside llama.cpp.
"""

from __future__ import annotations

import atexit
import ctypes
import math
from contextlib import contextmanager
from functools import lru_cache

from ara.errors import AraError


class GBNFError(AraError, ValueError):
    """A GBNF text that llama.cpp refuses to load."""


# The ctypes callback must outlive every call into llama.cpp, so it lives here.
_silent_log = None


@contextmanager
def muted_llama_log():
    """Silence llama.cpp's own log while loading a model.

    llama-cpp-python's ``verbose=False`` leaves some load-time lines through (a
    vocab-only model's context size complaint, the full-size SWA cache notice).
    """
    import llama_cpp
    from llama_cpp import _logger

    global _silent_log
    if _silent_log is None:
        _silent_log = llama_cpp.llama_log_callback(lambda level, text, user_data: None)
    llama_cpp.llama_log_set(_silent_log, ctypes.c_void_p(0))
    try:
        yield
    finally:
        llama_cpp.llama_log_set(_logger.llama_log_callback, ctypes.c_void_p(0))


@lru_cache(maxsize=4)
def _vocab_model(model_path: str):
    import llama_cpp

    with muted_llama_log():
        return llama_cpp.Llama(model_path=model_path, vocab_only=True, verbose=False)


# Free cached models while llama_cpp is still importable; left to interpreter
# teardown, their finalizers find its functions already gone.
atexit.register(_vocab_model.cache_clear)


class LlamaGrammarChecker:
    """Membership in a GBNF grammar, decided by llama.cpp.

    Args:
        gbnf: Grammar text whose start rule is ``root``.
        model_path: A GGUF whose vocabulary tokenizes the strings; defaults to the
            embedded Gemma 3 270M (only its vocabulary is loaded).

    Raises:
        GBNFError: If llama.cpp cannot parse ``gbnf``.
    """

    def __init__(self, gbnf: str, model_path: str | None = None) -> None:
        import llama_cpp

        self._llama_cpp = llama_cpp
        from ara.eval.translate.models import default_model_path

        self._model = _vocab_model(model_path or default_model_path())
        self._vocab = llama_cpp.llama_model_get_vocab(self._model._model.model)
        self._gbnf = gbnf.encode()
        probe = self._new_sampler()
        if not probe:
            raise GBNFError("llama.cpp could not parse the grammar (its log says where)")
        llama_cpp.llama_sampler_free(probe)

    def _new_sampler(self):
        return self._llama_cpp.llama_sampler_init_grammar(self._vocab, self._gbnf, b"root")

    def accepts(self, text: str) -> bool:
        """Whether the grammar admits ``text`` as a complete string."""
        lc = self._llama_cpp
        sampler = self._new_sampler()
        try:
            tokens = self._model.tokenize(text.encode(), add_bos=False, special=False)
            for token in tokens:
                if not self._allowed(sampler, token):
                    return False
                lc.llama_sampler_accept(sampler, token)
            return self._allowed(sampler, lc.llama_vocab_eos(self._vocab))
        finally:
            lc.llama_sampler_free(sampler)

    def _allowed(self, sampler, token: int) -> bool:
        lc = self._llama_cpp
        data = (lc.llama_token_data * 1)()
        data[0].id, data[0].logit, data[0].p = token, 0.0, 0.0
        candidates = lc.llama_token_data_array(data=data, size=1, selected=-1, sorted=False)
        lc.llama_sampler_apply(sampler, ctypes.byref(candidates))
        return not math.isinf(data[0].logit)
