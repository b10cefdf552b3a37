"""The HTTP backend against llama-cpp-python's real OpenAI-compatible server on loopback."""

import socket
import subprocess
import sys
import time
import urllib.request

import pytest

from ara.eval.backends.base import BackendError
from ara.eval.backends.openai_http import OpenAIBackend
from ara.eval.prompt import STOP, build_prompt
from ara.eval.translator import Translator

pytest.importorskip("uvicorn", reason="needs llama-cpp-python[server] (make setup)")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def server(embedded_model_path):
    """`python -m llama_cpp.server` with the embedded model, on a free loopback port."""
    port = free_port()
    proc = subprocess.Popen(
        [sys.executable, "-m", "llama_cpp.server", "--model", embedded_model_path,
         "--host", "127.0.0.1", "--port", str(port), "--n_ctx", "2048"],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    url = f"http://127.0.0.1:{port}"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        try:
            urllib.request.urlopen(f"{url}/v1/models", timeout=2)
            break
        except OSError:
            time.sleep(0.5)
    else:
        proc.kill()
        pytest.fail("llama_cpp.server did not start within 120 s")
    yield url
    proc.terminate()
    proc.wait(timeout=30)


def test_completion_through_the_server_matches_the_local_backend(server, llama_backend):
    """Tests that the endpoint's greedy answer is the local llama.cpp backend's answer."""
    prompt = build_prompt("always (prop_1) and eventually (prop_2)", ["prop_1", "prop_2"], [])
    remote = OpenAIBackend(server).complete(prompt, None, 32, STOP)
    local = llama_backend.complete(prompt, None, 32, STOP)
    assert remote.text == local.text and remote.completion_tokens > 0


def test_translator_parses_the_endpoint_answer(server):
    """Tests variant F through HTTP: the answer is parsed like any backend's."""
    result = Translator(OpenAIBackend(server)).translate(
        "eventually (prop_1)", ["prop_1"], constrained=False)
    assert result.raw.strip() and (result.valid or result.error)


def test_constrained_requests_and_dead_endpoints_are_refused(server):
    """Tests that C over HTTP is an error, and so is an endpoint nobody listens on."""
    with pytest.raises(BackendError, match="decodes freely"):
        Translator(OpenAIBackend(server)).translate("eventually (prop_1)", ["prop_1"])
    dead = OpenAIBackend(f"http://127.0.0.1:{free_port()}", timeout_s=5)
    with pytest.raises(BackendError, match="unreachable"):
        dead.complete("x", None, 4, STOP)
