"""Throughput of constrained translation against an inference server, by the number of
requests in flight (`ara eval ablation --concurrency N`), measured side by side in one run.

    .venv/bin/python bench/server_concurrency.py [--n 24] [--levels 1,2,4] [--url URL]

Without ``--url`` it starts llama-cpp-python's server on loopback with the embedded
Gemma 3 270M (the shipped adapter is not loaded: the server serves one model file), and
times ``--n`` hand-written grounded instructions, zero-shot, under each request's grammar
(sent as llama.cpp's ``grammar`` field). That server decodes one request at a time, so
its throughput should not grow with N; a batching server (vLLM, SGLang, llama.cpp's
``llama-server --parallel K``) is where N pays, and ``--url`` measures one.
"""

from __future__ import annotations

import argparse
import os
import platform
import random
import socket
import subprocess
import sys
import time
import urllib.request
from concurrent.futures import ThreadPoolExecutor

from ara.data import load_or_prepare
from ara.eval.translate.backends.openai_http import OpenAIBackend
from ara.eval.translate.translator import Translator


def start_loopback_server() -> tuple[str, subprocess.Popen]:
    from ara.eval.translate.models import default_model_path

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    proc = subprocess.Popen(
        [sys.executable, "-m", "llama_cpp.server", "--model", default_model_path(),
         "--host", "127.0.0.1", "--port", str(port), "--n_ctx", "2048"],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    url = f"http://127.0.0.1:{port}"
    for _ in range(240):
        try:
            urllib.request.urlopen(f"{url}/v1/models", timeout=2)
            return url, proc
        except OSError:
            time.sleep(0.5)
    proc.kill()
    raise SystemExit("llama_cpp.server did not start within 120 s")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=24, help="hand-written instructions")
    ap.add_argument("--levels", default="1,2,4", help="requests in flight, comma list")
    ap.add_argument("--url", help="a running server (default: llama_cpp.server on loopback)")
    ap.add_argument("--server", default="auto",
                    help="its flavour: auto (asked of the server), llama, vllm or sglang")
    args = ap.parse_args()
    records = random.Random(0).sample(load_or_prepare("handwritten").records("test", "grounded"),
                                      args.n)
    url, proc = (args.url, None) if args.url else start_loopback_server()
    try:
        backend = OpenAIBackend(url, server=args.server)
        translator = Translator(backend)
        translator.translate(records[0].nl, records[0].aps)  # warm-up
        print(f"# {args.n} constrained translations against {url} ({backend.server}); "
              f"{platform.machine()}, {os.cpu_count()} cores\n")
        print("| in flight | wall s | formulas/s | vs 1 | valid |\n|---:|---:|---:|---:|---:|")
        base = None
        for level in (int(x) for x in args.levels.split(",")):
            start = time.perf_counter()
            with ThreadPoolExecutor(level) as pool:
                results = list(pool.map(lambda r: translator.translate(r.nl, r.aps), records))
            wall = time.perf_counter() - start
            rate = len(records) / wall
            base = base or rate
            valid = sum(r.valid for r in results)
            print(f"| {level} | {wall:.1f} | {rate:.2f} | {rate / base:.2f}x | "
                  f"{valid}/{len(results)} |")
    finally:
        if proc is not None:
            proc.terminate()
            proc.wait(timeout=30)


if __name__ == "__main__":
    main()
