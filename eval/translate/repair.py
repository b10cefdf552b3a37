"""More answers than the greedy one: a self-consistency vote, and repair of an answer that
leaves part of the request out.

The vote (:func:`translate_consistent`): the greedy answer and ``samples - 1`` sampled
ones (seeded, under the same grammar, so all are valid) are grouped by Spot
equivalence, not by text: ``F(a) | F(b)`` and ``F(a | b)`` vote together. The largest
group wins; a tie goes to the group holding the greedy answer, so with one sample this
is plain greedy decoding. The cost is
``samples`` generations plus the Spot checks between distinct answers.

Repair (:func:`translate_repaired`) looks for another answer only when the greedy one
leaves out a listed proposition or a stated bound (:mod:`ara.eval.translate.checks`), and then
prefers the answers that leave out least; the greedy answer stays unless another says
more of the request. By default the other answers are samples drawn under the grammar
and the formulas one edit from the greedy one that write what it left out, and the
model's score of each whole answer picks among them; where the backend cannot score,
the samples' majority does. A complete greedy answer is checked by its score, which
decoding computes on the way: if the model gives it a probability below
:data:`~ara.eval.translate.confidence.DOUBT`, samples are drawn and the best-scored complete
answer wins (a search for the likelier answer that greedy decoding missed); otherwise
it stands.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, replace

from ara.errors import ConfigError
from ara.eval.translate.backends.base import Sampling
from ara.eval.translate.checks import gaps, mends
from ara.eval.translate.confidence import DOUBT, result_score
from ara.eval.translate.deadline import UNBOUNDED, Deadline
from ara.eval.translate.prompt import ANSWER_PREFIX, Shot
from ara.eval.translate.request import Request
from ara.eval.translate.translator import TranslationResult, Translator
from ara.grammars import parse, to_text
from ara.grammars.spot_bridge import same_meaning

#: Repair in ``ara translate`` and ``ara demo``: on, drawing this many answers. What
#: each way of repairing fixed and broke on the held-out sets: docs/what-moved.md.
DEFAULT_REPAIR = 8

#: The temperature repair and self-consistency draw their answers at.
TEMPERATURE = 0.7

#: How repair looks for a better answer (see :func:`translate_repaired`).
REPAIR_BY = ("samples+edits", "edits", "samples")

#: The help of each repair option, shared by ``ara translate``, ``translate-file`` and
#: ``ara eval ablation``; each command adds its own default for ``samples``.
REPAIR_HELP = {
    "samples": "K answers to draw, 0 to 32, when the first leaves part of the request out "
               "(a proposition, a stated bound, an order, an 'always' or 'at some point'), "
               "reads its 'whenever' clause as the consequence, or the model doubts it "
               f"(confidence below {DOUBT}); one with fewer gaps wins (not over http(s)://, "
               "which cannot draw).",
    "by": "samples+edits: the K answers drawn and the formulas one edit from the greedy "
          "answer that close a gap; the one the model scores highest of those with the "
          "fewest gaps wins. edits: the edits alone. samples: the majority of the K drawn "
          "with the fewest gaps.",
    "doubt": "With repair by samples+edits: also draw the K answers when the greedy answer "
             "leaves nothing out but the model gives it a probability below this, and keep "
             "the best-scored complete one. 0: repair answers with a gap only.",
    "temperature": "Sampling temperature for --samples and --repair.",
}


@dataclass(frozen=True)
class RepairConfig:
    """How :func:`translate_repaired` looks for a better answer than the greedy one.

    Attributes:
        samples: Extra answers to draw when the greedy one has a gap or is doubted, 0 to
            32 (0: greedy only); ``None``: :data:`DEFAULT_REPAIR`, where repair is on by
            default (:class:`~ara.eval.translate.answering.AnswerConfig` turns it off for a vote).
        by: One of :data:`REPAIR_BY`.
        doubt: By ``samples+edits``: also draw for a complete greedy answer the model
            gives a probability below this, 0 to 1 (0: gaps only).
        temperature: For the drawn answers, > 0.
        seed: Drawn answer ``i`` (from 1) has seed ``seed + i``.
    """

    samples: int | None = None
    by: str = REPAIR_BY[0]
    doubt: float = DOUBT
    temperature: float = TEMPERATURE
    seed: int = 0

    def __post_init__(self) -> None:
        if self.samples is not None and not 0 <= self.samples <= 32:
            raise ConfigError(f"repair draws 0 to 32 answers (--repair), got {self.samples}")
        if self.by not in REPAIR_BY:
            raise ConfigError(f"--repair-by {self.by!r}? choose one of {', '.join(REPAIR_BY)}")
        if not 0 <= self.doubt <= 1:
            raise ConfigError(f"doubt is a probability, 0 to 1 (0: gaps only); got {self.doubt}")
        if not 0 < self.temperature < math.inf:  # nan too
            raise ConfigError(f"temperature must be > 0, got {self.temperature}")

    @property
    def draws(self) -> int:
        """The number of answers repair may draw, the default resolved."""
        return DEFAULT_REPAIR if self.samples is None else self.samples


@dataclass(frozen=True)
class Vote:
    """The outcome of one self-consistent translation.

    Attributes:
        results: Every translation, greedy first.
        groups: Indices into ``results``, one tuple per meaning, largest first.
        ms: Wall time of all generations and checks.
        scores: The model's log-probability of each answer, where answers were scored
            (repair by score: those that leave out least); ``None`` for the others.
    """

    results: tuple[TranslationResult, ...]
    groups: tuple[tuple[int, ...], ...]
    ms: float
    scores: tuple[float | None, ...] = ()

    @property
    def result(self) -> TranslationResult:
        """The winning answer: the first generated of the largest group."""
        return self.results[self.groups[0][0]]

    @property
    def answers(self) -> tuple[str | None, ...]:
        """Every answer's formula, greedy first (``None`` where one did not parse)."""
        return tuple(r.stl for r in self.results)

    @property
    def agreement(self) -> float:
        """Share of the answers in the winning group."""
        return len(self.groups[0]) / len(self.answers)


def readings(vote: Vote, timeout_s: float = 10.0, limit: int | None = None,
             deadline: Deadline = UNBOUNDED) -> list[tuple[str, float]]:
    """The distinct meanings among a vote's scored answers, best-scored first: each as
    the text the model scored highest among those of that meaning, with that
    log-probability. The winner comes first where it was scored; answers equivalent
    by Spot are one reading (a check Spot cannot decide in ``timeout_s`` keeps both).
    With a ``limit``, the first ``limit`` readings only, which spares the Spot checks
    of the rest (seconds each on long formulas with large bounds); once ``deadline``
    is spent, those found by then."""
    kept: list[tuple[str, float]] = []
    for group in vote.groups:
        if limit is not None and len(kept) >= limit:
            break
        score = vote.scores[group[0]] if vote.scores else None
        if score is None:
            continue
        stl = vote.results[group[0]].stl
        if kept and deadline.spent():  # every further reading needs Spot checks
            break
        if not any(_same(stl, other, timeout_s, deadline) for other, _ in kept):
            kept.append((stl, score))
    return kept


def translate_consistent(translator: Translator, nl: str, aps: Sequence[str],
                         shots: Sequence[Shot] = (), samples: int = 5,
                         temperature: float = TEMPERATURE, seed: int = 0,
                         timeout_s: float = 10.0, grammar_in_prompt: bool = False,
                         deadline: Deadline = UNBOUNDED) -> Vote:
    """Translate ``nl`` ``samples`` times under the grammar and keep the majority meaning.

    Args:
        translator: Any translator whose backend can sample (the local ones).
        nl, aps, shots: As :meth:`Translator.translate`.
        samples: Answers to draw, >= 1 (the first is greedy).
        temperature: Sampling temperature, > 0.
        seed: Answer ``i`` is drawn with seed ``seed + i``.
        timeout_s: Spot's limit per comparison; an undecided pair counts as different.
        grammar_in_prompt: Show the grammar in every prompt (variant P).
        deadline: Once spent, no more answers are drawn or checked (greedy is made).
    """
    if samples < 1:
        raise ConfigError(f"samples must be >= 1, got {samples}")
    start = time.perf_counter()
    results = [translator.translate(nl, aps, shots, grammar_in_prompt)]
    results += _draw(translator, nl, aps, shots, samples - 1, temperature, seed,
                     grammar_in_prompt, deadline)
    groups = _group([r.stl for r in results], timeout_s, deadline)
    ranked = sorted(groups, key=lambda g: (-len(g), g[0]))
    return Vote(tuple(results), tuple(ranked), (time.perf_counter() - start) * 1e3)


def translate_repaired(translator: Translator, nl: str, aps: Sequence[str],
                       shots: Sequence[Shot] = (), repair: RepairConfig = RepairConfig(),
                       timeout_s: float = 10.0, grammar_in_prompt: bool = False,
                       deadline: Deadline = UNBOUNDED) -> Vote:
    """Translate ``nl`` greedily; if the answer leaves out part of the request, look for
    one that leaves out less, and if the model doubts it, for one it scores higher.

    Args:
        translator, nl, aps, shots, timeout_s, grammar_in_prompt, deadline: As
            :func:`translate_consistent`; a spent deadline also stops mending and
            scoring, and the greedy answer stays unless a scored one beats it.
        repair: How many answers to draw (``samples``), and how (``by``):
            ``samples+edits``: draw ``samples`` answers under the grammar, add the
            formulas one edit from the greedy answer that write what it left out
            (:func:`literal_mends`), and keep the model's best-scored answer among
            those that leave out least. ``edits``: the same without the samples
            (drawn only if no edit fits the request's grammar). ``samples``: keep the
            majority meaning among the samples that leave out least, which is also
            what the other two do where the backend cannot score.
            ``doubt``: by ``samples+edits`` on a backend that scores, when the greedy answer
            leaves nothing out but the model gives it a probability below ``doubt``
            (:mod:`ara.eval.translate.confidence`), draw ``samples`` answers and keep the
            best-scored of those and the greedy one that leave nothing out (an answer
            above 0.5 is the likeliest there is, so nothing is drawn for it); 0: act
            on gaps only.

    Returns:
        A :class:`Vote` of one answer when the greedy one leaves nothing out (and is
        not doubted), ``samples`` is 0, or the backend can neither score nor sample (an
        HTTP server); a backend that cannot sample draws none. Otherwise of all answers
        considered, greedy first. With a gap, the greedy answer wins unless another
        leaves out less. Ranked by score, answers
        of the same text share a group, best score first; a mended answer's result is
        the greedy one's with the formula replaced (timings and token counts are the
        greedy call's).
    """
    samples, by, doubt = repair.draws, repair.by, repair.doubt
    temperature, seed = repair.temperature, repair.seed
    start = time.perf_counter()
    request = Request.of(nl, aps)
    greedy = translator.translate(nl, aps, shots, grammar_in_prompt)
    # Without intervals no answer can write a bound: only the other gaps count.
    bounds = translator.config.intervals
    gap = _missing(request, greedy.stl, bounds)
    helpless = not translator.can_score and not translator.backend.can_sample
    if not samples or gap == float("inf") or helpless:
        return Vote((greedy,), ((0,),), (time.perf_counter() - start) * 1e3)
    if not gap:
        return _unless_doubted(translator, request, greedy, shots, samples, temperature, seed,
                               grammar_in_prompt, doubt if by == "samples+edits" else 0.0,
                               start, deadline)
    if by != "samples" and translator.can_score:
        drawn = (_draw(translator, nl, aps, shots, samples, temperature, seed,
                       grammar_in_prompt, deadline) if by == "samples+edits" else [])
        mended = [] if deadline.spent() else literal_mends(translator, request, greedy.stl, bounds)
        if drawn or mended:
            results = [greedy, *drawn, *(replace(greedy, raw=ANSWER_PREFIX + text, stl=text)
                                         for text in mended)]
            return _ranked_by_score(translator, request, results, shots, grammar_in_prompt,
                                    greedy_stays=True, start=start, deadline=deadline)
    results = [greedy, *_draw(translator, nl, aps, shots, samples, temperature, seed,
                              grammar_in_prompt, deadline)]
    ranked = rank_repairs([r.stl for r in results],
                          [_missing(request, r.stl, bounds) for r in results], timeout_s,
                          deadline)
    return Vote(tuple(results), tuple(ranked), (time.perf_counter() - start) * 1e3)


def _unless_doubted(translator: Translator, request: Request, greedy: TranslationResult,
                    shots: Sequence[Shot], samples: int, temperature: float, seed: int,
                    grammar_in_prompt: bool, doubt: float, start: float,
                    deadline: Deadline) -> Vote:
    """The complete greedy answer, with its score where the backend scores; if the model
    gives it a probability below ``doubt``, the best-scored of it and ``samples`` drawn
    answers that leave nothing out."""
    if not doubt or not translator.can_score:
        return Vote((greedy,), ((0,),), (time.perf_counter() - start) * 1e3)
    score = result_score(translator, greedy, shots, grammar_in_prompt)  # decoding's, if any
    if math.exp(score) >= doubt or deadline.spent():
        return Vote((greedy,), ((0,),), (time.perf_counter() - start) * 1e3, (score,))
    results = [greedy, *_draw(translator, request.nl, request.aps, shots, samples,
                              temperature, seed, grammar_in_prompt, deadline)]
    return _ranked_by_score(translator, request, results, shots, grammar_in_prompt,
                            greedy_stays=False, start=start, deadline=deadline)


def _ranked_by_score(translator: Translator, request: Request,
                     results: Sequence[TranslationResult], shots: Sequence[Shot],
                     grammar_in_prompt: bool, greedy_stays: bool, start: float,
                     deadline: Deadline) -> Vote:
    """A vote over ``results`` (greedy first) by the model's score of those that leave
    out least (:func:`score_complete`, :func:`rank_scored`), grouped by text; none
    scored once ``deadline`` is spent (the greedy answer first)."""
    answers = [r.stl for r in results]
    missing = [_missing(request, a, translator.config.intervals) for a in answers]
    scores = ([None] * len(answers) if deadline.spent() else
              score_complete(translator, request.nl, request.aps, answers, missing, shots,
                             grammar_in_prompt))
    order = rank_scored(missing, scores, greedy_stays)
    return Vote(tuple(results), _same_text(results, order),
                (time.perf_counter() - start) * 1e3, tuple(scores))


def score_complete(translator: Translator, nl: str, aps: Sequence[str],
                   answers: Sequence[str | None], missing: Sequence[float],
                   shots: Sequence[Shot] = (),
                   grammar_in_prompt: bool = False) -> list[float | None]:
    """The model's score of each answer that leaves out least (``missing[i]``: how much
    answer ``i`` leaves out), ``None`` for the rest; an answer given twice is scored
    once."""
    least = min(missing)
    pool = sorted({a for a, m in zip(answers, missing, strict=True) if m == least})
    scored = dict(zip(pool, translator.score(nl, aps, [parse(a) for a in pool], shots,
                                             grammar_in_prompt), strict=True))
    return [scored[a] if m == least else None for a, m in zip(answers, missing, strict=True)]


def rank_scored(missing: Sequence[float], scores: Sequence[float | None],
                greedy_stays: bool = True) -> list[int]:
    """Indices of answers (greedy first) ranked by score, the scored ones first; as with
    samples, the greedy answer stays first unless another leaves out less (unless not
    ``greedy_stays``: then it competes by score like the rest)."""
    stays = greedy_stays and missing[0] == min(missing)
    return sorted(range(len(missing)), key=lambda i: (
        scores[i] is None, not (stays and i == 0), -(scores[i] or 0)))


def _same_text(results: Sequence[TranslationResult],
               order: Sequence[int]) -> tuple[tuple[int, ...], ...]:
    """``order`` grouped by formula text, each group where its first member stands: a
    sample that repeats another answer votes with it, as in :attr:`Vote.agreement`."""
    groups: dict[str | None, list[int]] = {}
    for i in order:
        groups.setdefault(results[i].stl, []).append(i)
    return tuple(tuple(g) for g in groups.values())


def rank_repairs(answers: Sequence[str | None], missing: Sequence[float],
                 timeout_s: float = 10.0,
                 deadline: Deadline = UNBOUNDED) -> list[tuple[int, ...]]:
    """Groups of ``answers`` (greedy first), the winner first.

    ``missing[i]`` is how much of the request answer ``i`` leaves out. If no answer
    leaves out less than the greedy one, the greedy one's group wins; otherwise the
    largest group of the answers that leave out least (answers that leave out more
    stand alone, after them). Answers a spent ``deadline`` leaves unchecked stand alone.
    """
    least = min(missing)
    if least == missing[0]:
        ranked = _group(answers, timeout_s, deadline)
        ranked.sort(key=lambda g: (g[0] != 0, -len(g), g[0]))
    else:
        best = [a if m == least else None for a, m in zip(answers, missing, strict=True)]
        ranked = _group(best, timeout_s, deadline)
        ranked.sort(key=lambda g: (missing[g[0]] != least, -len(g), g[0]))
    return ranked


def literal_mends(translator: Translator, request: Request, stl: str,
                  bounds: bool = True) -> list[str]:
    """Formulas one edit from ``stl`` that close one of its gaps
    (:func:`~ara.eval.translate.checks.mends`; without ``bounds``, not a stated bound), kept to
    the request's language so that each is an answer constrained decoding could have
    given."""
    syntax = translator.grammar(request.aps, request.nl).syntax
    texts = dict.fromkeys(map(to_text, mends(request, parse(stl), bounds)))
    texts.pop(stl, None)
    return [text for text in texts if syntax.accepts(text)]


def _draw(translator: Translator, nl: str, aps: Sequence[str], shots: Sequence[Shot],
          n: int, temperature: float, seed: int,
          grammar_in_prompt: bool, deadline: Deadline) -> list[TranslationResult]:
    if not translator.backend.can_sample:
        return []
    return [translator.translate(nl, aps, shots, grammar_in_prompt,
                                 sampling=Sampling(temperature=temperature, seed=seed + i))
            for i in range(1, n + 1) if not deadline.spent()]


def _missing(request: Request, stl: str | None, bounds: bool = True) -> float:
    """How much of the request an answer leaves out (an unparsed one: everything);
    without ``bounds``, every gap but the bounds left out counts."""
    return float("inf") if stl is None else gaps(request, parse(stl)).count(timed=bounds)


def _group(answers: Sequence[str | None], timeout_s: float,
           deadline: Deadline = UNBOUNDED) -> list[tuple[int, ...]]:
    """Indices of equivalent answers together; unparsed answers each stand alone."""
    groups: list[list[int]] = []
    for i, text in enumerate(answers):
        home = None
        if text is not None:
            for g in groups:
                first = answers[g[0]]
                if first is not None and _same(text, first, timeout_s, deadline):
                    home = g
                    break
        if home is None:
            groups.append([i])
        else:
            home.append(i)
    return [tuple(g) for g in groups]


def _same(a: str, b: str, timeout_s: float, deadline: Deadline = UNBOUNDED) -> bool:
    """Whether Spot finds ``a`` and ``b`` the same within ``timeout_s`` and ``deadline``."""
    if a == b:
        return True
    if deadline.spent():
        return False
    same = same_meaning(a, b, deadline.within(timeout_s))
    if same is None:
        deadline.spent()  # the budget, not the check's own limit, may have stopped it
    return same is True
