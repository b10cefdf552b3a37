"""The project's error hierarchy.

Every error raised on bad input derives from :class:`AraError` *and* from the matching
builtin, so callers may catch either ``AraError`` or ``ValueError``.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable


class AraError(Exception):
    """Base class of every error this toolkit raises on purpose."""


class STLSyntaxError(AraError, ValueError):
    """A formula that does not belong to the language.

    Attributes:
        text: The text that was parsed.
        position: 0-based character offset of the offending token.
        reason: What was wrong there, and what was expected instead.
    """

    def __init__(self, text: str, position: int, reason: str) -> None:
        self.text = text
        self.position = position
        self.reason = reason
        # A window of the text around the position: a 10,000-character input would
        # otherwise bury the message.
        start = max(0, position - _CONTEXT)
        shown = text[start:position + _CONTEXT]
        prefix = "..." if start else ""
        suffix = "..." if position + _CONTEXT < len(text) else ""
        caret = " " * (len(prefix) + position - start) + "^"
        super().__init__(f"{reason} at position {position}:\n  {prefix}{shown}{suffix}\n"
                         f"  {caret}")


_CONTEXT = 60


class BoundTooLargeError(AraError, ValueError):
    """A time bound beyond what an operation is documented to handle."""


class DataVersionError(AraError, ValueError):
    """A prepared data split whose files do not match its manifest."""


class ConfigError(AraError, ValueError):
    """A configuration value out of range, or an unknown key."""


def did_you_mean(name: str, available: Iterable[str]) -> str:
    """Return a hint naming the closest valid choice and listing them all.

    Args:
        name: The name that was given.
        available: The names that would have been accepted.

    Returns:
        A sentence such as ``"Did you mean 'paper'? Available: disjoint, paper."``.
    """
    choices = sorted(available)
    close = difflib.get_close_matches(name, choices, n=1)
    hint = f"Did you mean '{close[0]}'? " if close else ""
    return f"{hint}Available: {', '.join(choices)}."


def refuse_unknown_keys(data: Iterable[str], known: Iterable[str], where: str = "") -> None:
    """Raise :class:`ConfigError` on the first key of ``data`` not in ``known``, naming it
    under ``where`` (``"lora."``) with the closest known key: a misspelt setting would
    otherwise be dropped without a word."""
    known = set(known)
    for key in data:
        if key not in known:
            raise ConfigError(f"unknown key {where}{key}. {did_you_mean(str(key), known)}")
