"""Natural language to STL: translators over local and remote models, and the paper's
F/P/C ablation judged by Spot.

* :mod:`ara.eval.translator`: prompt a backend under the request's own grammar.
* :mod:`ara.eval.backends`: llama.cpp (the embedded GGUF), transformers, HTTP servers.
* :mod:`ara.eval.harness`, :mod:`ara.eval.ablation`: resumable evaluation runs.
* :mod:`ara.eval.models`: what ``--model`` names (the shipped adapters among them).
"""
