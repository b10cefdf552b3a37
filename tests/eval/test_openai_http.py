"""The HTTP backend against llama-cpp-python's real OpenAI-compatible server on loopback."""

import os
import socket
import subprocess
import sys
import time
import urllib.request

import pytest

from ara.eval.translate.backends.base import BackendError
from ara.eval.translate.backends.openai_http import OpenAIBackend
from ara.eval.translate.prompt import STOP, Shot, build_prompt
from ara.eval.translate.translator import Translator

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


def test_translator_parses_the_endpoint_answer(server, llama_backend):
    """Tests variant F through HTTP: the answer is parsed as the local backend's is."""
    nl, aps = "eventually (prop_1)", ["prop_1"]
    remote = Translator(OpenAIBackend(server)).translate(nl, aps, constrained=False)
    local = Translator(llama_backend).translate(nl, aps, constrained=False)
    assert remote.raw.strip() and (remote.stl, remote.error) == (local.stl, local.error)


def test_an_endpoint_cannot_score_answers_and_repair_keeps_its_answer(server):
    """Tests that scoring answers, which repair ranks by, is refused by name on a
    server, and that repair, which can neither score nor sample there, keeps the
    greedy answer of a request it would repair on a local model."""
    from ara.eval.translate.checks import gaps
    from ara.eval.translate.repair import translate_repaired
    from ara.eval.translate.request import Request
    from ara.grammars import parse

    translator = Translator(OpenAIBackend(server, server="llama"))
    assert not translator.can_score
    with pytest.raises(BackendError, match="cannot score answers; use a local model"):
        translator.score("eventually (prop_1)", ["prop_1"], [parse("F(prop_1)")])
    nl, aps = "within 20 steps reach (prop_1), and never (prop_2)", ("prop_1", "prop_2")
    greedy = translator.translate(nl, aps)
    assert gaps(Request.of(nl, aps), parse(greedy.stl)), \
        f"{greedy.stl} leaves nothing out: choose a sentence it leaves a bound out of"
    vote = translate_repaired(translator, nl, aps)
    assert vote.answers == (greedy.stl,)


@pytest.mark.slow  # llama.cpp's grammar sampler over HTTP: seconds an answer
def test_constrained_decoding_on_the_server_equals_the_local_backend(server, llama_backend,
                                                                      paper_split):
    """Tests F+P+C over HTTP: the request's grammar travels in llama.cpp's field, every
    answer is valid, and greedy answers equal the local llama.cpp backend's."""
    records = paper_split.records("test", "lifted")[:3]
    shots = [Shot.of(r) for r in paper_split.records("train", "lifted")[:3]]
    # llama.cpp's grammar sampler checks the whole vocabulary at each step: seconds
    remote = Translator(OpenAIBackend(server, server="llama", timeout_s=900))
    local = Translator(llama_backend)
    for r in records:
        there = remote.translate(r.nl, r.aps, shots, grammar_in_prompt=True)
        here = local.translate(r.nl, r.aps, shots, grammar_in_prompt=True)
        assert there.valid and there.grammar["grammar_sha256"]
        assert there.stl == here.stl, r.nl


def test_constrained_requests_to_plain_openai_and_dead_endpoints_are_refused(server):
    """Tests that C needs a server that reads grammars, and that an endpoint nobody
    listens on is an error."""
    with pytest.raises(BackendError, match="--server llama"):
        Translator(OpenAIBackend(server, server="openai")).translate("eventually (prop_1)",
                                                                     ["prop_1"])
    dead = OpenAIBackend(f"http://127.0.0.1:{free_port()}", timeout_s=5, server="llama")
    with pytest.raises(BackendError, match="unreachable"):
        dead.complete("x", None, 4, STOP)


def test_llama_cpp_python_says_which_server_it_is(server):
    """Tests --server auto, the default, against the real llama-cpp-python server."""
    assert OpenAIBackend(server).server == "llama"


def _decoding_grammar(aps=("prop_1", "prop_2")):
    from ara.eval.translate.translator import TranslatorConfig, decoding_grammar
    from ara.grammars import build_grammar

    return decoding_grammar(build_grammar(TranslatorConfig().syntax(aps, "no numbers")))


@pytest.mark.parametrize(("flavour", "fields"), [
    ("llama", lambda g: {"grammar": g}),
    ("vllm", lambda g: {"structured_outputs": {"grammar": g}}),  # guided_grammar is gone
    ("sglang", lambda g: {"ebnf": g}),
])
def test_each_server_gets_the_grammar_in_its_documented_field(flavour, fields):
    """Tests the request bodies against the servers' documented field names, with the
    request's own GBNF (vLLM and SGLang cannot run on these machines)."""
    grammar = _decoding_grammar()
    backend = OpenAIBackend("http://127.0.0.1:9", server=flavour)
    assert backend.grammar_fields(grammar) == fields(grammar.grammar.to_gbnf())
    assert backend.grammar_fields(None) == {}
    with pytest.raises(BackendError, match="server must be one of"):
        OpenAIBackend("http://127.0.0.1:9", server="tgi")


@pytest.mark.parametrize(("listing", "flavour"), [
    ({"data": [{"id": "gemma", "owned_by": "llamacpp"}]}, "llama"),  # llama.cpp
    ({"data": [{"id": "gemma", "owned_by": "vllm"}]}, "vllm"),
    ({"data": [{"id": "gemma", "owned_by": "sglang"}]}, "sglang"),
    ({"data": [{"id": "gpt-4", "owned_by": "openai"}]}, "openai"),  # says nothing
    ({"object": "list", "data": []}, "openai"),
    ({"data": {"id": "x"}}, "openai"), ({"data": ["x"]}, "openai"), ([1], "openai"),
    ({"data": [{"owned_by": ["vllm"]}]}, "openai"),
    (404, "openai"), (501, "openai"),  # no model list at all
])
def test_a_server_is_known_by_the_name_it_gives_itself(listing, flavour):
    """Tests what --server auto reads into each answer of GET /v1/models: only a name a
    server is known to give itself picks its grammar field; a listing of another shape
    means plain OpenAI."""
    httpd = listing_server(listing)
    try:
        assert OpenAIBackend(url_of(httpd)).server == flavour
    finally:
        httpd.shutdown()


@pytest.mark.parametrize(("listing", "says"), [
    (401, "set \\$OPENAI_API_KEY"), (403, "set \\$OPENAI_API_KEY"),
    (503, "(?s)HTTP 503.*name the server with --server"),  # llama-server still loading
    (b"<html>log in</html>", "did not answer as an OpenAI-compatible server"),
])
def test_a_server_that_will_not_say_which_it_is_is_an_error_that_says_what_to_do(listing,
                                                                                  says):
    """Tests --server auto where the answer cannot be read: an error naming the fix, never
    a silent guess that would refuse every constrained request later."""
    httpd = listing_server(listing)
    try:
        with pytest.raises(BackendError, match=says):
            OpenAIBackend(url_of(httpd))
    finally:
        httpd.shutdown()
    with pytest.raises(BackendError, match="unreachable"):  # nobody to ask
        OpenAIBackend(f"http://127.0.0.1:{free_port()}", timeout_s=5)


def listing_server(listing):
    """A real HTTP server on loopback, started: GET /v1/models answers ``listing`` (JSON, or
    those bytes, or an int: that HTTP error); a POST is answered like a vLLM which ignores
    unknown fields: 200 and free text, whatever grammar it was sent. ``.received`` holds
    each POST's path and body."""
    import json
    import threading
    from http.server import BaseHTTPRequestHandler, HTTPServer

    class Handler(BaseHTTPRequestHandler):
        def do_GET(self):  # noqa: N802 (the stdlib's name)
            if isinstance(listing, int) or self.path != "/v1/models":
                self.send_error(listing if isinstance(listing, int) else 404)
                return
            body = listing if isinstance(listing, bytes) else json.dumps(listing).encode()
            self.send_response(200)
            self.send_header("Content-Type", "application/json")
            self.end_headers()
            self.wfile.write(body)

        def do_POST(self):  # noqa: N802 (the stdlib's name)
            asked = json.loads(self.rfile.read(int(self.headers["Content-Length"])))
            received.append((self.path, asked))
            text = " eventually prop_1 holds"
            choice = ({"message": {"role": "assistant", "content": text}}
                      if self.path.endswith("/chat/completions") else {"text": text})
            body = json.dumps({"choices": [{**choice, "finish_reason": "stop"}]}).encode()
            self.send_response(200)
            self.send_header("Content-Type", "application/json")
            self.end_headers()
            self.wfile.write(body)

        def log_message(self, *args):
            pass

    received: list[tuple[str, dict]] = []
    httpd = HTTPServer(("127.0.0.1", 0), Handler)
    httpd.received = received
    threading.Thread(target=httpd.serve_forever, daemon=True).start()
    return httpd


@pytest.fixture()
def deaf_server():
    """A vLLM that ignores the grammar field (:func:`listing_server`)."""
    httpd = listing_server({"data": [{"id": "default", "owned_by": "vllm"}]})
    yield httpd
    httpd.shutdown()


def url_of(httpd) -> str:
    return f"http://127.0.0.1:{httpd.server_address[1]}"


def test_a_server_that_ignores_the_grammar_stops_the_run(deaf_server):
    """Tests that free text from a server that dropped the grammar field is an error
    naming the field and what to check, not a silently invalid answer."""
    translator = Translator(OpenAIBackend(url_of(deaf_server), server="vllm"))
    with pytest.raises(BackendError, match="ignored the grammar.*structured_outputs"):
        translator.translate("eventually (prop_1)", ["prop_1"])


@pytest.mark.parametrize(("suffix", "path", "name"), [
    ("", "/v1/completions", "default"),
    ("#google/gemma-3-12b-it", "/v1/completions", "google/gemma-3-12b-it"),
    ("#chat:gpt-4", "/v1/chat/completions", "gpt-4"),
])
def test_the_url_names_the_served_model_and_the_api(deaf_server, suffix, path, name):
    """Tests what --model http://...#NAME sends: the model name a vLLM serves, and with
    chat: the prompt as one user message to a chat model (the paper's GPT-4 baseline)."""
    from ara.eval.translate.models import make_backend

    backend = make_backend(url_of(deaf_server) + suffix)
    answer = backend.complete("NL: go\nSTL:", None, 16, STOP)
    assert answer.text == " eventually prop_1 holds"
    (asked_path, asked), = deaf_server.received
    assert asked_path == path and asked["model"] == name
    assert ("messages" in asked) == ("chat" in path)


@pytest.mark.skipif(not os.environ.get("ARA_TEST_SERVER_URL"),
                    reason="set ARA_TEST_SERVER_URL to a running server to test it live "
                           "(and ARA_TEST_SERVER=llama|vllm|sglang if it does not say "
                           "which it is)")
def test_a_live_server_decodes_under_the_grammar():
    """Tests constrained translation against a server you run (e.g. vLLM with Gemma 3
    12B): the answer is a formula over the request's propositions."""
    backend = OpenAIBackend(os.environ["ARA_TEST_SERVER_URL"],
                            os.environ.get("ARA_TEST_SERVER_MODEL", "default"),
                            server=os.environ.get("ARA_TEST_SERVER", "auto"))
    result = Translator(backend).translate("always avoid (prop_1) and eventually reach "
                                           "(prop_2)", ["prop_1", "prop_2"])
    assert result.valid and result.constrained


@pytest.mark.slow  # two ablations over HTTP; the server's answers are tested above
def test_concurrent_requests_keep_the_serial_log(server, tmp_path, llama_backend):
    """Tests --concurrency: with three requests in flight the samples are the serial
    run's, in the same order, a resumed run adds none twice, and a local backend
    refuses concurrency."""
    from ara.errors import ConfigError
    from ara.eval.ablation import run_ablation
    from ara.eval.harness import AblationConfig
    from ara.run_store import read_samples

    config = AblationConfig(variants=("F", "C"), shots=(2,), reruns=1, limit=3,
                            spot_timeout_s=5)
    backend = OpenAIBackend(server, server="llama", timeout_s=900)
    run_ablation(config, backend, tmp_path / "serial", progress=False)
    run_ablation(config, backend, tmp_path / "parallel", progress=False, concurrency=3)

    def answers(folder):
        return [(s["variant"], s["uid"], s["raw"]) for s in read_samples(folder)]

    assert answers(tmp_path / "parallel") == answers(tmp_path / "serial")
    assert len(answers(tmp_path / "serial")) == 6
    run_ablation(config, backend, tmp_path / "parallel", resume=True, progress=False,
                 concurrency=3)
    assert len(answers(tmp_path / "parallel")) == 6
    with pytest.raises(ConfigError, match="needs a remote backend"):
        run_ablation(config, llama_backend, tmp_path / "local", progress=False, concurrency=2)
