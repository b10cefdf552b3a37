"""ask-reason-assist: natural language to Signal Temporal Logic, with guaranteed syntax.

The areas of the toolkit are subpackages, each kept in its own top-level folder of the
repository and mapped into this namespace by ``pyproject.toml``: ``ara.grammars``,
``ara.data``, ``ara.training``, ``ara.eval``, ``ara.coordination``.
"""

__version__ = "0.1.0"

#: What ``import ara`` offers directly (:mod:`ara.api`), loaded on first use so that
#: importing the package stays cheap.
API = ("translate", "explain", "equivalent", "translator")


def __getattr__(name: str):
    if name in API:
        from ara import api

        return getattr(api, name)
    raise AttributeError(f"module 'ara' has no attribute {name!r}")
