"""Tokens of the STL surface syntax, with the whitespace that precedes each one.

Keeping the whitespace lets :mod:`ara.grammars.syntax` decide membership in a
grammar's language (which fixes where spaces may go) from the same tokens the
parser reads, so the parser and the grammars never disagree on lexing.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from enum import Enum

from ara.errors import STLSyntaxError


class Kind(Enum):
    WORD = "word"  # identifiers and the keywords F G X U true false inf
    NUMBER = "number"
    PUNCT = "punct"
    END = "end"


# Longest punctuation first: "<->" before "->", so maximal munch holds.
_PUNCT = ("<->", "->", "(", ")", "[", "]", ",", "!", "~", "&", "|")
_TOKEN = re.compile(
    r"(?P<ws>\s*)(?:(?P<word>[A-Za-z_][A-Za-z0-9_]*)|(?P<number>[0-9]+)|(?P<punct>"
    + "|".join(re.escape(p) for p in _PUNCT)
    + r"))"
)


@dataclass(frozen=True, slots=True)
class Token:
    """One token.

    Attributes:
        kind: Lexical class.
        text: The token's characters ("" for END).
        start: Offset of its first character in the source.
        space: The whitespace between the previous token (or the start) and this one.
    """

    kind: Kind
    text: str
    start: int
    space: str


def tokenize(text: str) -> list[Token]:
    """Split ``text`` into tokens, ending with one END token.

    Raises:
        STLSyntaxError: At the first character that starts no token.
    """
    tokens: list[Token] = []
    pos = 0
    while True:
        match = _TOKEN.match(text, pos)
        if match is None:
            ws_end = len(text) - len(text[pos:].lstrip())
            if ws_end == len(text):
                tokens.append(Token(Kind.END, "", len(text), text[pos:]))
                return tokens
            raise STLSyntaxError(
                text, ws_end, f"unexpected character {text[ws_end]!r}; operators are "
                "! ~ & | -> <-> F G X U, intervals look like [2,5]"
            )
        kind = Kind(match.lastgroup)
        body = match.group(match.lastgroup)
        tokens.append(Token(kind, body, match.start(match.lastgroup), match.group("ws")))
        pos = match.end()
