"""An OpenAI-compatible HTTP endpoint: the paper's GPT-4 baseline, variants F and F+P.

Uses only the standard library. ``api="completions"`` sends the prompt as is (base
models, llama.cpp's server); ``api="chat"`` sends it as one user message (GPT-4 and
other chat models). The key, if the endpoint needs one, comes from
``$OPENAI_API_KEY``. The endpoint decodes freely: constrained variants need a local
backend, and asking this one for a grammar is an error, not a silent downgrade.
"""

from __future__ import annotations

import json
import os
import time
import urllib.error
import urllib.request

from ara.eval.backends.base import BackendError, Completion, Sampling
from ara.grammars import BuiltGrammar


class OpenAIBackend:
    """Completions from ``{base_url}/v1/completions`` or ``/v1/chat/completions``.

    Args:
        base_url: E.g. ``http://127.0.0.1:8000`` (with or without a trailing ``/v1``).
        model: Model name the endpoint expects.
        api: ``completions`` or ``chat``.
        timeout_s: Seconds to wait for one answer.
    """

    def __init__(self, base_url: str, model: str = "default", api: str = "completions",
                 timeout_s: float = 120.0) -> None:
        if api not in ("completions", "chat"):
            raise BackendError(f"api must be 'completions' or 'chat', got {api!r}")
        self.base_url = base_url.rstrip("/").removesuffix("/v1")
        self.model, self.api, self.timeout_s = model, api, timeout_s
        self.model_id = f"http:{self.base_url}:{model}"

    def _post(self, path: str, body: dict) -> dict:
        headers = {"Content-Type": "application/json"}
        if key := os.environ.get("OPENAI_API_KEY"):
            headers["Authorization"] = f"Bearer {key}"
        request = urllib.request.Request(f"{self.base_url}/v1/{path}",
                                         data=json.dumps(body).encode(), headers=headers)
        try:
            with urllib.request.urlopen(request, timeout=self.timeout_s) as response:
                return json.loads(response.read())
        except urllib.error.HTTPError as err:
            detail = err.read().decode(errors="replace")[:300]
            raise BackendError(f"{self.base_url} answered HTTP {err.code}: {detail}") from err
        except (urllib.error.URLError, TimeoutError, ConnectionError) as err:
            raise BackendError(
                f"endpoint {self.base_url} is unreachable ({err}); is the server running?"
            ) from err

    def complete(self, prompt: str, grammar: BuiltGrammar | None, max_tokens: int,
                 stop: str, sampling: Sampling | None = None) -> Completion:
        if sampling is not None:
            raise BackendError("sampling (self-consistency) runs on local models only")
        if grammar is not None:
            raise BackendError(
                "an HTTP endpoint decodes freely: run constrained variants (C) with a local "
                "model (default, a .gguf path or hf:...)"
            )
        body = {"model": self.model, "max_tokens": max_tokens, "temperature": 0.0,
                "stop": [stop]}
        start = time.perf_counter()
        if self.api == "chat":
            answer = self._post("chat/completions",
                                {**body, "messages": [{"role": "user", "content": prompt}]})
            text = answer["choices"][0]["message"]["content"]
        else:
            answer = self._post("completions", {**body, "prompt": prompt})
            text = answer["choices"][0]["text"]
        usage = answer.get("usage") or {}
        reason = answer["choices"][0].get("finish_reason")
        return Completion(text, usage.get("prompt_tokens", 0),
                          usage.get("completion_tokens", 0), 0,
                          (time.perf_counter() - start) * 1e3,
                          "length" if reason == "length" else "stop")
