"""One instruction in, one answer out, as ``ara translate`` gives it to a user.

``ara translate``, ``ara translate-file``, :func:`ara.translate`, the ablation harness and
``ara demo`` share this: the translation (greedy, voted or repaired), the model's
confidence in it, the other readings it weighed when it doubts, and what the answer
leaves out of the request. Each answer is an :class:`Answer`; its :meth:`Answer.to_json`
is the ``--json`` object and one line of a ``translate-file`` output.
"""

from __future__ import annotations

import math
import random
from collections.abc import Sequence
from dataclasses import dataclass, replace
from functools import lru_cache
from pathlib import Path

from ara.errors import ConfigError
from ara.eval.translate.checks import Gaps, gaps
from ara.eval.translate.confidence import (
    DOUBT,
    doubt_warning,
    result_probability,
    winner_probability,
)
from ara.eval.translate.deadline import Deadline
from ara.eval.translate.prompt import Shot, sample_shots
from ara.eval.translate.repair import (
    REPAIR_BY,
    TEMPERATURE,
    RepairConfig,
    Vote,
    readings,
    translate_consistent,
    translate_repaired,
)
from ara.eval.translate.request import Request
from ara.eval.translate.request_file import read_pairs
from ara.eval.translate.translator import TranslationResult, Translator, TranslatorConfig
from ara.grammars import parse

#: Seconds Spot may take to tell whether two readings mean the same; an undecided pair
#: is listed as two. Long formulas with bounds in the hundreds can take minutes, and a
#: user waits for this list.
SAME_READING_TIMEOUT_S = 2.0

#: Seconds an answer may take by default before repair, its Spot checks and the other
#: readings stop and the best answer found so far is given.
BUDGET_S = 5.0


@dataclass(frozen=True)
class AnswerConfig:
    """How to answer: the search, and what to report beside the formula.

    Attributes:
        samples: Self-consistency: greedy + ``samples - 1`` sampled answers, the largest
            group by meaning wins; 1: no vote. 1 to 32.
        repair: How extra answers are drawn, by repair and by the vote; repair draws
            ``repair.samples`` (``None``: :data:`DEFAULT_REPAIR`, or 0 with ``samples``
            or unconstrained).
        grammar_in_prompt: Show the grammar in the prompt.
        constrained: Decode under the grammar.
        alternatives: Other readings to report when the model doubts its answer, 0 to 8.
        budget_s: Seconds for the whole answer (:class:`~ara.eval.translate.deadline.Deadline`):
            once spent, repair draws, mends and scores no more answers, Spot checks
            stop and the greedy answer (or a better one already scored) is given. >= 0;
            0 or ``None``: unbounded.
    """

    samples: int = 1
    repair: RepairConfig = RepairConfig()
    grammar_in_prompt: bool = False
    constrained: bool = True
    alternatives: int = 2
    budget_s: float | None = BUDGET_S

    def __post_init__(self) -> None:
        if not 1 <= self.samples <= 32:
            raise ConfigError(f"samples must be 1 to 32, got {self.samples}")
        if self.samples > 1 and not self.constrained:
            raise ConfigError("--samples decodes under the grammar (every sample valid); "
                              "drop --no-constraint")
        if self.samples > 1 and self.repair.samples:
            raise ConfigError("--samples and --repair are two ways to spend extra answers; "
                              "pass one")
        if self.repair.samples and not self.constrained:
            raise ConfigError("--repair decodes under the grammar; drop --no-constraint")
        if not 0 <= self.alternatives <= 8:
            raise ConfigError(f"alternatives must be 0 to 8, got {self.alternatives}")
        if self.budget_s is not None and not 0 <= self.budget_s < math.inf:
            raise ConfigError(f"the budget is seconds per answer, >= 0 (0: unbounded); got "
                              f"{self.budget_s}")
        object.__setattr__(self, "budget_s", self.budget_s or None)  # one way to say none

    @classmethod
    def of(cls, samples: int = 1, repair: int | None = None, repair_by: str = REPAIR_BY[0],
           doubt: float = DOUBT, temperature: float = TEMPERATURE, seed: int = 0,
           **rest) -> AnswerConfig:
        """The config of ``ara translate``'s options, named as the command names them."""
        return cls(samples, RepairConfig(repair, repair_by, doubt, temperature, seed), **rest)

    @property
    def repairs(self) -> int:
        """The number of answers repair draws, the default resolved."""
        if self.repair.samples is None and (self.samples > 1 or not self.constrained):
            return 0
        return self.repair.draws


@dataclass(frozen=True)
class Answer:
    """One answer to a request, and what a user should know of it.

    Attributes:
        result: The winning translation (a mend's is the greedy one's with the formula
            replaced).
        model: The backend's model id.
        vote: Every answer weighed, where more than one could be (a vote or repair).
        confidence: The model's probability of the answer, to 3 significant digits;
            ``None`` where the backend cannot score, or nobody asked.
        alternatives: Other readings, each formula with its probability, listed only
            when the confidence is below :data:`DOUBT`.
        gaps: What the answer leaves out of the request or nests unasked
            (:class:`~ara.eval.translate.checks.Gaps`); ``None`` where it does not parse, or
            nobody asked.
        waited_ms: The whole time :func:`answer` took (generation, scoring, readings,
            gap checks); ``None`` where the answer was made otherwise.
        budget_s: The time budget it was given; ``None``: unbounded.
        ran_out: Whether the budget ran out before the search was done (a draw, mend,
            score, Spot check or reading was skipped or cut short), so that an unbounded
            answer may differ; not where nothing was left to do (a greedy answer slower
            than the budget, with no gap and no doubt).
    """

    result: TranslationResult
    model: str = ""
    vote: Vote | None = None
    confidence: float | None = None
    alternatives: tuple[tuple[str, float], ...] = ()
    gaps: Gaps | None = None
    waited_ms: float | None = None
    budget_s: float | None = None
    ran_out: bool = False

    @property
    def stl(self) -> str | None:
        """The formula in canonical text, ``None`` if the model wrote none."""
        return self.result.stl

    @property
    def ms(self) -> float:
        """The time a user waited for the answer, in milliseconds: :attr:`waited_ms`, else
        that of every generation and check."""
        if self.waited_ms is not None:
            return self.waited_ms
        return self.vote.ms if self.vote else self.result.ms

    @property
    def attempts(self) -> int:
        """Generations weighed (more than one: voted or repaired)."""
        return len(self.vote.results) if self.vote else 1

    def to_json(self) -> dict:
        """The ``--json`` object of ``ara translate``: ``stl``, ``valid``, ``raw``, ``ms``
        (the whole answer), ``budget`` (``s``, the seconds given, ``null``: unbounded;
        ``ran_out``), ``error``, ``model``, ``constrained``, ``shots``, ``grammar``;
        ``samples`` (every answer, their groups and scores) where more than one was
        weighed; ``confidence``; ``alternatives`` (each ``stl`` and ``probability``);
        ``left_out``, ``unasked`` and ``condition``
        (:meth:`~ara.eval.translate.checks.Gaps.to_json`) where the answer parses."""
        r, vote = self.result, self.vote
        data = {"stl": r.stl, "valid": r.valid, "raw": r.raw, "ms": round(self.ms, 1),
                "budget": {"s": self.budget_s, "ran_out": self.ran_out}, "error": r.error,
                "model": self.model, "constrained": r.constrained,
                "shots": r.shots, "grammar": r.grammar}
        if vote is not None:
            data["samples"] = {"answers": list(vote.answers),
                               "groups": [list(g) for g in vote.groups],
                               "agreement": round(vote.agreement, 3)}
            if vote.scores:
                data["samples"]["scores"] = [None if x is None else round(x, 3)
                                             for x in vote.scores]
        data["confidence"] = self.confidence
        data["alternatives"] = [{"stl": stl, "probability": p} for stl, p in self.alternatives]
        return data | (self.gaps.to_json() if self.gaps is not None else {})


def answer(translator: Translator, nl: str, aps: Sequence[str], shots: Sequence[Shot] = (),
           config: AnswerConfig | None = None) -> Answer:
    """Translate ``nl`` over ``aps`` as ``config`` says, with what a user should know: the
    model's confidence, the other readings where it doubts the answer
    (:data:`DOUBT`), and the answer's gaps (:func:`~ara.eval.translate.checks.gaps`), all within
    ``config.budget_s`` (:class:`~ara.eval.translate.deadline.Deadline`)."""
    config = config or AnswerConfig()
    deadline = Deadline(config.budget_s)
    vote: Vote | None = None
    repair = config.repair
    if config.samples > 1:
        vote = translate_consistent(translator, nl, aps, shots, config.samples,
                                    repair.temperature, repair.seed,
                                    grammar_in_prompt=config.grammar_in_prompt,
                                    deadline=deadline)
        result = vote.result
    elif config.repairs:
        vote = translate_repaired(translator, nl, aps, shots,
                                  replace(repair, samples=config.repairs),
                                  grammar_in_prompt=config.grammar_in_prompt,
                                  deadline=deadline)
        result = vote.result
    else:
        result = translator.translate(nl, aps, shots, config.grammar_in_prompt,
                                      constrained=config.constrained)
    probability = (winner_probability(translator, vote, shots, config.grammar_in_prompt)
                   if vote else result_probability(translator, result, shots,
                                                   config.grammar_in_prompt))
    confidence = None if probability is None else _significant(probability)
    others: tuple[tuple[str, float], ...] = ()
    if doubted(confidence) and vote is not None:
        # The winner is scored whenever anything is, so the first reading is its.
        others = tuple((stl, _significant(math.exp(score)))
                       for stl, score in readings(vote, SAME_READING_TIMEOUT_S,
                                                  1 + config.alternatives, deadline)[1:])
    found = None if result.stl is None else gaps(Request.of(nl, aps), parse(result.stl))
    return Answer(result, translator.backend.model_id, vote, confidence, others, found,
                  deadline.elapsed_ms, config.budget_s, deadline.ran_out)


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
            (the pool's pairs most like this request, :mod:`ara.eval.translate.similar`).
        pool: A file of one's own pairs to choose from (the lines `translate-file`
            reads, each with its reference); default: the compositional train side.
    """
    from ara.data.normalize import form_of
    from ara.eval.translate.models import default_shots
    from ara.eval.translate.similar import EXAMPLES_BY

    if by not in EXAMPLES_BY:
        raise ConfigError(f"examples by {by!r}? choose one of {', '.join(EXAMPLES_BY)}")
    k = shots if shots is not None else default_shots(model)
    if not k:
        return []
    form, source = form_of(tuple(aps)), None if pool is None else str(pool)
    records = _pool(form, source)
    if k > len(records):
        raise ConfigError(f"{k} worked examples asked for (--shots), but the pool has only "
                          f"{len(records)} {form} pairs")
    if by == "similar":
        return [Shot.of(r) for r in _pool_index(form, source).nearest(nl, aps, k)]
    return sample_shots(list(records), k, random.Random(seed))


# A process that translates many requests reads and indexes a pool once, not per request.
@lru_cache(maxsize=8)
def _pool(form: str, path: str | None) -> tuple:
    if path is None:
        from ara.data import load_or_prepare  # prepares the split on first use

        return tuple(load_or_prepare("compositional").records("train", form))
    return tuple(r for r in read_pairs(Path(path), TranslatorConfig()) if r.form == form)


@lru_cache(maxsize=8)
def _pool_index(form: str, path: str | None):
    from ara.eval.translate.similar import index_for

    return index_for(_pool(form, path))


def notes(answer: Answer, nl: str = "") -> list[str]:
    """What to tell a user about an answer, as ``ara translate`` prints it on stderr:
    whether its time budget ran out, what it leaves out of the request (quoting the words
    of ``nl`` that ask for it), and, if the model doubts it, the answer read back with
    the other readings it weighed."""
    if answer.stl is None:
        return []
    said = []
    if answer.ran_out:
        said.append(f"note: the time budget of {answer.budget_s:g} s ran out before the search "
                    "for a better answer was done; this is the best found by then (--budget "
                    "sets it, 0: no limit)")
    if answer.gaps:
        said.append(answer.gaps.warning(Request.of(nl, ())))  # no aps here: read nl whole
    if doubted(answer.confidence):
        said.append(doubt_warning(answer.stl, answer.confidence, list(answer.alternatives)))
    return said


def doubted(confidence: float | None) -> bool:
    """Whether the model gives an answer (its ``confidence``) less than :data:`DOUBT`."""
    return confidence is not None and confidence < DOUBT
