"""The translation prompt: instructions, few-shot examples, optional grammar, the query.

Training imports :func:`format_example` from here so that fine-tuning sees exactly
the layout evaluation prompts with. The query comes last and the parts that do not
depend on it come first, so consecutive prompts share a long prefix whose KV cache a
backend can reuse.
"""

from __future__ import annotations

import hashlib
import random
from collections.abc import Sequence
from dataclasses import dataclass

from ara.data.normalize import Record
from ara.grammars import Syntax, build_grammar

INSTRUCTIONS = (
    "Translate each instruction into Signal Temporal Logic (STL) over the given atomic "
    "propositions.\n"
    "Operators: ! not, & and, | or, -> implies, <-> iff, F eventually, G always, U until; "
    "F[a,b], G[a,b] and U[a,b] hold within time steps a to b.\n"
)
#: Ends the answer line; backends stop generating at it when unconstrained.
STOP = "\n"
#: The space a model writes after "STL:"; part of the decoding grammar, stripped after.
ANSWER_PREFIX = " "


@dataclass(frozen=True)
class Shot:
    """One worked example: sentence, propositions, formula."""

    nl: str
    aps: tuple[str, ...]
    stl: str

    @classmethod
    def of(cls, record: Record) -> Shot:
        return cls(record.nl, record.aps, record.stl)


def format_example(nl: str, aps: Sequence[str], stl: str | None = None) -> str:
    """One example block; without ``stl`` it is the open query the model completes.

    The answer follows ``"STL: "``; training puts its loss on the answer alone.
    """
    block = f"NL: {nl}\nPropositions: {', '.join(aps)}\nSTL:"
    return block if stl is None else f"{block}{ANSWER_PREFIX}{stl}{STOP}\n"


def grammar_for_prompt(syntax: Syntax) -> str:
    """The grammar as shown to the model (variant P): the GBNF, with the interval
    rules (an exact digit trie, thousands of lines) summarized in one line."""
    gbnf = build_grammar(syntax).grammar.to_gbnf()
    lines = [ln for ln in gbnf.splitlines() if not ln.startswith(("lo", "ge-", "interval "))]
    if syntax.intervals and syntax.bounds is not None:
        lines.append(f'interval ::= "[" lo "," hi "]"  # lo <= hi, each one of '
                     f'{", ".join(map(str, syntax.bounds))}')
    elif syntax.intervals:
        lines.append(f'interval ::= "[" lo "," hi "]"  # integers, 0 <= lo <= hi <= '
                     f'{syntax.max_bound}')
    return "\n".join(lines)


def build_prompt(nl: str, aps: Sequence[str], shots: Sequence[Shot],
                 grammar: str | None = None) -> str:
    """The full prompt for one query.

    Args:
        nl: The instruction to translate.
        aps: Its atomic propositions.
        shots: Worked examples, in order (variant F).
        grammar: Grammar text to include (variant P), or ``None``.
    """
    parts = [INSTRUCTIONS, "\n"]
    parts += [format_example(s.nl, s.aps, s.stl) for s in shots]
    if grammar is not None:
        parts.append(f"Every answer is a string of this grammar (GBNF):\n{grammar}\n\n")
    parts.append(format_example(nl, aps))
    return "".join(parts)


def sample_shots(pool: Sequence[Record], k: int, rng: random.Random) -> list[Shot]:
    """``k`` distinct worked examples drawn from ``pool`` (training records)."""
    if k > len(pool):
        raise ValueError(f"asked for {k} shots from a pool of {len(pool)} records")
    return [Shot.of(r) for r in rng.sample(list(pool), k)]


def prompt_sha256(prompt: str) -> str:
    return hashlib.sha256(prompt.encode()).hexdigest()[:16]
