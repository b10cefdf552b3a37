"""One instruction in, one answer out, as ``ara translate`` gives it to a user.

``ara translate`` and ``ara translate-file`` share this: the translation (greedy, voted
or repaired), the model's confidence in it, the other readings it weighed when it
doubts, and what the answer leaves out of the request. Each answer is a plain dict, the
``--json`` object and one line of a ``translate-file`` output.
"""

from __future__ import annotations

import math
import random
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

from ara.errors import ConfigError
from ara.eval.checks import Gaps, gaps
from ara.eval.confidence import DOUBT, doubt_warning, result_probability, winner_probability
from ara.eval.consistency import (
    DEFAULT_REPAIR,
    REPAIR_BY,
    Vote,
    readings,
    translate_consistent,
    translate_repaired,
)
from ara.eval.prompt import Shot, sample_shots
from ara.eval.request import Request
from ara.eval.translator import Translator
from ara.grammars import parse

#: Seconds Spot may take to tell whether two readings mean the same; an undecided pair
#: is listed as two. Long formulas with bounds in the hundreds can take minutes, and a
#: user waits for this list.
SAME_READING_TIMEOUT_S = 2.0


@dataclass(frozen=True)
class AnswerConfig:
    """How to answer: the search, and what to report beside the formula.

    Attributes:
        samples: Self-consistency: greedy + ``samples - 1`` sampled answers, the largest
            group by meaning wins; 1: no vote. 1 to 32.
        repair: Extra answers to draw where the greedy one leaves out part of the
            request or the model doubts it (:func:`translate_repaired`); 0: off.
            ``None``: :data:`DEFAULT_REPAIR`, or 0 with ``samples`` or unconstrained.
        repair_by: One of :data:`REPAIR_BY`.
        doubt: Probability below which repair by samples+edits searches a complete
            answer too, 0 to 1 (0: gaps only).
        temperature: For the sampled answers, > 0.
        seed: Sampled answer ``i`` is drawn with seed ``seed + i``.
        grammar_in_prompt: Show the grammar in the prompt.
        constrained: Decode under the grammar.
        alternatives: Other readings to report when the model doubts its answer, 0 to 8.
    """

    samples: int = 1
    repair: int | None = None
    repair_by: str = REPAIR_BY[0]
    doubt: float = DOUBT
    temperature: float = 0.7
    seed: int = 0
    grammar_in_prompt: bool = False
    constrained: bool = True
    alternatives: int = 2

    def __post_init__(self) -> None:
        if not 1 <= self.samples <= 32:
            raise ConfigError(f"samples must be 1 to 32, got {self.samples}")
        if self.repair is not None and not 0 <= self.repair <= 32:
            raise ConfigError(f"repair must be 0 to 32, got {self.repair}")
        if self.samples > 1 and not self.constrained:
            raise ConfigError("--samples decodes under the grammar (every sample valid); "
                              "drop --no-constraint")
        if self.samples > 1 and self.repair:
            raise ConfigError("--samples and --repair are two ways to spend extra answers; "
                              "pass one")
        if self.repair and not self.constrained:
            raise ConfigError("--repair decodes under the grammar; drop --no-constraint")
        if self.repair_by not in REPAIR_BY:
            raise ConfigError(f"--repair-by {self.repair_by!r}? choose one of "
                              f"{', '.join(REPAIR_BY)}")
        if not 0 <= self.doubt <= 1:
            raise ConfigError(f"doubt is a probability, 0 to 1; got {self.doubt}")
        if self.temperature <= 0:
            raise ConfigError(f"temperature must be > 0, got {self.temperature}")
        if not 0 <= self.alternatives <= 8:
            raise ConfigError(f"alternatives must be 0 to 8, got {self.alternatives}")

    @property
    def repairs(self) -> int:
        """The number of answers repair draws, the default resolved."""
        if self.repair is not None:
            return self.repair
        return 0 if self.samples > 1 or not self.constrained else DEFAULT_REPAIR


def answer(translator: Translator, nl: str, aps: Sequence[str], shots: Sequence[Shot] = (),
           config: AnswerConfig | None = None) -> dict:
    """Translate ``nl`` over ``aps`` as ``config`` says, with what a user should know.

    Returns:
        The ``--json`` object of ``ara translate``: ``stl``, ``valid``, ``raw``, ``ms``
        (all generations), ``error``, ``model``, ``constrained``, ``shots``,
        ``grammar``; ``samples`` (every answer, their groups and scores) where more
        than one was weighed; ``confidence`` (the model's probability of the answer,
        ``None`` where the backend cannot score); ``alternatives`` (other readings, each
        ``stl`` and ``probability``, listed only when the confidence is below
        :data:`DOUBT`); ``left_out`` (listed propositions and stated bounds the answer
        never uses; ``order``: whether it orders nothing where the sentence asks
        for one step after another; ``claims``: ``G``, ``F``, ``G(F)`` the sentence asks
        for in words and the answer never writes, :func:`~ara.eval.checks.unclaimed`)
        and ``unasked`` (subformulas nesting temporal
        operators or ordering steps as the sentence never asks,
        :func:`~ara.eval.checks.unasked`), where the answer parses.
    """
    config = config or AnswerConfig()
    vote: Vote | None = None
    if config.samples > 1:
        vote = translate_consistent(translator, nl, aps, shots, config.samples,
                                    config.temperature, config.seed,
                                    grammar_in_prompt=config.grammar_in_prompt)
        result = vote.result
    elif config.repairs:
        vote = translate_repaired(translator, nl, aps, shots, config.repairs,
                                  config.temperature, config.seed,
                                  grammar_in_prompt=config.grammar_in_prompt,
                                  by=config.repair_by, doubt=config.doubt)
        result = vote.result
    else:
        result = translator.translate(nl, aps, shots, config.grammar_in_prompt,
                                      constrained=config.constrained)
    data = {"stl": result.stl, "valid": result.valid, "raw": result.raw,
            "ms": round(vote.ms if vote else result.ms, 1), "error": result.error,
            "model": translator.backend.model_id, "constrained": result.constrained,
            "shots": len(shots), "grammar": result.grammar}
    if vote is not None:
        data["samples"] = {"answers": list(vote.answers), "groups": [list(g) for g in vote.groups],
                           "agreement": round(vote.agreement, 3)}
        if vote.scores:
            data["samples"]["scores"] = [None if x is None else round(x, 3)
                                         for x in vote.scores]
    probability = (winner_probability(translator, vote, shots, config.grammar_in_prompt)
                   if vote else result_probability(translator, result, shots,
                                                   config.grammar_in_prompt))
    data["confidence"] = None if probability is None else _significant(probability)
    others: list[tuple[str, float]] = []
    if doubted(data) and vote is not None:
        # The winner is scored whenever anything is, so the first reading is its.
        others = [(stl, math.exp(score))
                  for stl, score in readings(vote, SAME_READING_TIMEOUT_S,
                                             limit=1 + config.alternatives)[1:]]
    data["alternatives"] = [{"stl": stl, "probability": _significant(p)} for stl, p in others]
    if result.stl is not None:
        data |= gaps(Request.of(nl, aps), parse(result.stl)).to_json()
    return data


def _significant(p: float) -> float:
    """``p`` to 3 significant digits: a reading the model gives 0.0004 is not 0."""
    return float(f"{p:.3g}")


def worked_examples(model: str, shots: int | None, aps: Sequence[str], seed: int = 0,
                    nl: str = "", by: str = "random",
                    pool: str | Path | None = None) -> list[Shot]:
    """The worked examples a prompt for ``nl`` over ``aps`` shows.

    Args:
        model: The ``--model``; it sets the default count.
        shots: How many (``None``: the model's default, none for the fine-tuned adapters).
        aps: The request's propositions: examples are of their form (lifted or grounded).
        seed: Which examples ``random`` draws.
        nl: The request's sentence, which ``similar`` compares the pool's with.
        by: ``random`` (the same examples for every request of a form) or ``similar``
            (the pool's pairs most like this request, :mod:`ara.eval.similar`).
        pool: A file of one's own pairs to choose from (the lines `translate-file`
            reads, each with its reference); default: the compositional train side.
    """
    from ara.data.normalize import form_of
    from ara.eval.models import default_shots
    from ara.eval.similar import EXAMPLES_BY, index_for

    if by not in EXAMPLES_BY:
        raise ConfigError(f"examples by {by!r}? choose one of {', '.join(EXAMPLES_BY)}")
    k = shots if shots is not None else default_shots(model)
    if not k:
        return []
    form = form_of(tuple(aps))
    if pool is None:
        from ara.data import load_or_prepare  # prepares the split on first use

        records = load_or_prepare("compositional").records("train", form)
    else:
        records = [r for r in _pool_file(str(pool)) if r.form == form]
    if k > len(records):
        raise ConfigError(f"{k} worked examples asked for (--shots), but the pool has only "
                          f"{len(records)} {form} pairs")
    if by == "similar":
        return [Shot.of(r) for r in index_for(records).nearest(nl, aps, k)]
    return sample_shots(records, k, random.Random(seed))


@lru_cache(maxsize=4)
def _pool_file(path: str) -> tuple:
    from ara.eval.translator import TranslatorConfig
    from ara.eval.user_data import read_pairs

    return tuple(read_pairs(Path(path), TranslatorConfig()))


def notes(data: dict, nl: str = "") -> list[str]:
    """What to tell a user about an answer (:func:`answer`'s dict), as ``ara translate``
    prints it on stderr: what it leaves out of the request (quoting the words of ``nl``
    that ask for it), and, if the model doubts it, the answer read back with the other
    readings it weighed."""
    if data["stl"] is None:
        return []
    said = []
    gap = Gaps.from_json(data)
    if gap:
        said.append(gap.warning(Request.of(nl, ())))  # data lists no aps: read nl whole
    if doubted(data):
        others = [(a["stl"], a["probability"]) for a in data["alternatives"]]
        said.append(doubt_warning(data["stl"], data["confidence"], others))
    return said


def doubted(data: dict) -> bool:
    """Whether the model gives an answer (:func:`answer`'s dict) less than :data:`DOUBT`."""
    return data["confidence"] is not None and data["confidence"] < DOUBT
