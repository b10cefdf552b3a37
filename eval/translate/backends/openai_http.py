"""An OpenAI-compatible HTTP endpoint: a model served elsewhere (Gemma 3 12B on a GPU
box), or the paper's GPT-4 baseline.

Uses only the standard library. ``api="completions"`` sends the prompt as is (base
models, llama.cpp's server); ``api="chat"`` sends it as one user message (GPT-4 and
other chat models). The key, if the endpoint needs one, comes from
``$OPENAI_API_KEY``.

Constrained decoding (variant C) sends the request's own grammar in the field the
server reads (:data:`GRAMMAR_FIELDS`), in GBNF, which llama.cpp reads natively and
vLLM's and SGLang's grammar backends (xgrammar by default) read as EBNF:

* ``llama``: llama.cpp's server and llama-cpp-python's, ``"grammar": GBNF``;
* ``vllm``: ``"structured_outputs": {"grammar": GBNF}`` (vLLM >= 0.12; the older
  ``guided_grammar`` was removed and unknown fields are silently ignored);
* ``sglang``: ``"ebnf": GBNF``;
* ``openai``: no grammar field; a constrained request is refused.

``auto`` (the default) asks the server who it is: llama.cpp's, vLLM's and SGLang's
servers each name themselves in ``owned_by`` of ``GET /v1/models`` (llama-cpp-python's
says ``me``); any other answer, OpenAI's own API included, is taken as ``openai``.

A server that ignores the field answers 200 with free text. Every constrained answer
is therefore checked against the grammar here, and one outside it stops the run with
an error that says so, never a silent drop in validity.
"""

from __future__ import annotations

import http.client
import json
import os
import time
import urllib.error
import urllib.request

from ara.eval.translate.backends.base import BackendError, Completion, Sampling
from ara.grammars import BuiltGrammar

#: Where each server flavour reads a grammar; ``openai`` has none.
GRAMMAR_FIELDS = {"llama": "grammar", "vllm": "structured_outputs.grammar",
                  "sglang": "ebnf", "openai": None}
#: ``owned_by`` of ``GET /v1/models`` as each server writes it in its source, and the
#: flavour it means. Only values a server is known to use for itself: OpenAI's API and
#: proxies answer ``openai``, ``system`` or an organisation, which say nothing.
OWNED_BY = {"llamacpp": "llama", "me": "llama", "vllm": "vllm", "sglang": "sglang"}
#: What ``server`` may be: a flavour, or ``auto`` to ask the server.
SERVERS = ("auto", *GRAMMAR_FIELDS)
#: Seconds to wait for the server to say which it is (a firewalled host never answers).
PROBE_S = 10.0
#: What to upgrade or set when a flavour's server ignored the grammar.
_FIX = {"llama": "a llama.cpp server (any recent build) or llama-cpp-python[server]",
        "vllm": "vLLM >= 0.12 with a structured-outputs backend (xgrammar, guidance)",
        "sglang": "SGLang with a grammar backend (xgrammar by default)"}


class OpenAIBackend:
    """Completions from ``{base_url}/v1/completions`` or ``/v1/chat/completions``.

    Args:
        base_url: E.g. ``http://127.0.0.1:8000`` (with or without a trailing ``/v1``).
        model: Model name the endpoint expects.
        api: ``completions`` or ``chat``.
        timeout_s: Seconds to wait for one answer.
        server: The server's flavour, which says where it reads a grammar
            (:data:`GRAMMAR_FIELDS`), or ``auto``: asked of the server once, here.

    Raises:
        BackendError: If an argument is unknown, or ``auto`` finds nobody listening.
    """

    #: Requests may be in flight at once (``--concurrency``): the server batches them.
    concurrent = True
    #: Seeded sampling under a grammar is not a call these servers share; repair reads
    #: this and keeps the greedy answer instead of failing.
    can_sample = False

    def __init__(self, base_url: str, model: str = "default", api: str = "completions",
                 timeout_s: float = 120.0, server: str = "auto") -> None:
        if api not in ("completions", "chat"):
            raise BackendError(f"api must be 'completions' or 'chat', got {api!r}")
        if server not in SERVERS:
            raise BackendError(f"server must be one of {list(SERVERS)}, got {server!r}")
        self.base_url = base_url.rstrip("/").removesuffix("/v1")
        self.model, self.api, self.timeout_s = model, api, timeout_s
        self.server = self.detect_server() if server == "auto" else server
        self.model_id = f"http:{self.base_url}:{model}"

    def detect_server(self) -> str:
        """The flavour the server names itself as (:data:`OWNED_BY`), else ``openai``."""
        try:
            listing = self._call("models", timeout_s=min(self.timeout_s, PROBE_S))
        except BackendError as err:
            code = getattr(err.__cause__, "code", None)
            if code in (404, 405, 501):
                return "openai"  # it answers, but lists no models: a server of another kind
            if code in (401, 403):
                raise BackendError(
                    f"{self.base_url} refused to say which server it is (HTTP {code}): set "
                    "$OPENAI_API_KEY to its key, or name the server with --server") from err
            raise BackendError(f"{err}; or name the server with --server, which skips "
                               "asking it") from err
        models = listing.get("data") if isinstance(listing, dict) else None
        first = models[0] if isinstance(models, list) and models else None
        if not isinstance(first, dict):
            return "openai"  # a listing of another shape names no server
        return OWNED_BY.get(str(first.get("owned_by")), "openai")

    def _call(self, path: str, body: dict | None = None,
              timeout_s: float | None = None) -> dict:
        """POST ``body`` to ``/v1/{path}``, or GET it where there is none; the answer's
        JSON."""
        headers = {"Content-Type": "application/json"}
        if key := os.environ.get("OPENAI_API_KEY"):
            headers["Authorization"] = f"Bearer {key}"
        request = urllib.request.Request(
            f"{self.base_url}/v1/{path}", headers=headers,
            data=None if body is None else json.dumps(body).encode())
        try:
            with urllib.request.urlopen(request, timeout=timeout_s or self.timeout_s) as response:
                return json.loads(response.read())
        except urllib.error.HTTPError as err:
            detail = err.read().decode(errors="replace")[:300]
            raise BackendError(f"{self.base_url} answered HTTP {err.code}: {detail}") from err
        except (urllib.error.URLError, TimeoutError, ConnectionError) as err:
            raise BackendError(
                f"endpoint {self.base_url} is unreachable ({err}); is the server running?"
            ) from err
        except (ValueError, http.client.HTTPException) as err:  # not JSON, or not HTTP
            raise BackendError(f"{self.base_url}/v1/{path} did not answer as an "
                               f"OpenAI-compatible server does: {err}") from err

    def complete(self, prompt: str, grammar: BuiltGrammar | None, max_tokens: int,
                 stop: str, sampling: Sampling | None = None) -> Completion:
        if sampling is not None:
            raise BackendError("sampling (self-consistency) runs on local models only")
        body = {"model": self.model, "max_tokens": max_tokens, "temperature": 0.0,
                "stop": [stop], **self.grammar_fields(grammar)}
        start = time.perf_counter()
        if self.api == "chat":
            answer = self._call("chat/completions",
                                {**body, "messages": [{"role": "user", "content": prompt}]})
            text = answer["choices"][0]["message"]["content"]
        else:
            answer = self._call("completions", {**body, "prompt": prompt})
            text = answer["choices"][0]["text"]
        usage = answer.get("usage") or {}
        reason = answer["choices"][0].get("finish_reason")
        if grammar is not None:
            self._check_obeyed(grammar, text, stop)
        return Completion(text, usage.get("prompt_tokens", 0),
                          usage.get("completion_tokens", 0), 0,
                          (time.perf_counter() - start) * 1e3,
                          "length" if reason == "length" else "stop")

    def grammar_fields(self, grammar: BuiltGrammar | None) -> dict:
        """The request body's fields that carry ``grammar`` to this server flavour."""
        if grammar is None:
            return {}
        where = GRAMMAR_FIELDS[self.server]
        if where is None:
            raise BackendError(
                f"the server at {self.base_url} is taken as plain OpenAI (it did not name "
                "itself as llama.cpp, vLLM or SGLang, or --server openai was given), which "
                "cannot decode under a grammar: name the server that runs it with --server "
                "llama, vllm or sglang, or use a local model (finetuned, a .gguf path or "
                "hf:FOLDER)")
        gbnf = grammar.grammar.to_gbnf()
        if "." in where:
            outer, inner = where.split(".")
            return {outer: {inner: gbnf}}
        return {where: gbnf}

    def _check_obeyed(self, grammar: BuiltGrammar, text: str, stop: str) -> None:
        """That a constrained answer is in the grammar's language (the budget always
        fits the grammar's longest string, so a cut answer is a disobeyed one too)."""
        from ara.eval.translate.translator import admits

        if admits(grammar, text.removesuffix(stop)):
            return
        raise BackendError(
            f"the server at {self.base_url} ignored the grammar: it answered {text!r}, which "
            f"the request's grammar does not admit. It was sent as "
            f"{GRAMMAR_FIELDS[self.server]!r} for --server {self.server}; check that the "
            f"server is {_FIX[self.server]}, and that --server names it")
