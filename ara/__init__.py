"""ask-reason-assist: natural language to Signal Temporal Logic, with guaranteed syntax.

The areas of the toolkit are subpackages, each kept in its own top-level folder of the
repository and mapped into this namespace by ``pyproject.toml``: ``ara.grammars``,
``ara.data``, ``ara.training``, ``ara.eval``, ``ara.coordination``.
"""

__version__ = "0.1.0"
