"""How sure the model is of its answer: a check that needs no reference.

The model's probability of its own answer, teacher-forced after the very prompt it
answered (:meth:`~ara.eval.translate.translator.Translator.score`), separates right from wrong
answers well on the held-out sets (measured in docs/model-card.md, "How repair and the
confidence note work"); a sentence the model cannot read ("( prop_1 ) purple elephant
( prop_2 )") gets a low one.

It mostly flags: the model seldom scores the reference above its own wrong answer.
Where it does, greedy decoding missed a likelier answer, and repair looks for it: where the
model doubts a complete answer, it keeps the best-scored of it and the samples
(:func:`~ara.eval.translate.repair.translate_repaired`). A user who sees the flag reads the
answer back (`ara stl explain`) or rewords the sentence.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

from ara.eval.translate.prompt import Shot
from ara.eval.translate.translator import TranslationResult, Translator
from ara.grammars import parse
from ara.grammars.english import explain

if TYPE_CHECKING:  # repair imports DOUBT from here
    from ara.eval.translate.repair import Vote

#: Below this probability an answer is flagged. Chosen on the compositional test side,
#: where the answers below it were more often wrong than right, and then checked on the
#: other held-out sets (docs/model-card.md).
DOUBT = 0.5


def answer_probability(translator: Translator, nl: str, aps: Sequence[str], stl: str | None,
                       shots: Sequence[Shot] = (),
                       grammar_in_prompt: bool = False) -> float | None:
    """The model's probability of ``stl`` as the whole answer to ``nl`` (ending it), or
    ``None`` where there is no answer or the backend cannot score (an HTTP server).

    Pass the ``shots`` and ``grammar_in_prompt`` the answer was translated with: the
    probability is of the answer to that prompt.
    """
    if stl is None or not translator.can_score:
        return None
    return math.exp(translator.score(nl, aps, [parse(stl)], shots, grammar_in_prompt)[0])


def result_score(translator: Translator, result: TranslationResult,
                 shots: Sequence[Shot] = (), grammar_in_prompt: bool = False) -> float | None:
    """The model's log-probability of a translation's answer: the one decoding summed on
    the way where it has one (no second pass), else a scoring pass; ``None`` where there
    is no answer or the backend cannot score."""
    if result.logprob is not None:
        return result.logprob
    if result.stl is None or not translator.can_score:
        return None
    return translator.score(result.nl, result.aps, [parse(result.stl)], shots,
                            grammar_in_prompt)[0]


def result_probability(translator: Translator, result: TranslationResult,
                       shots: Sequence[Shot] = (),
                       grammar_in_prompt: bool = False) -> float | None:
    """:func:`answer_probability` of a translation's answer, from :func:`result_score`."""
    score = result_score(translator, result, shots, grammar_in_prompt)
    return None if score is None else math.exp(score)


def winner_probability(translator: Translator, vote: Vote, shots: Sequence[Shot] = (),
                       grammar_in_prompt: bool = False) -> float | None:
    """:func:`answer_probability` of a vote's winner, from the scores repair already
    has where it scored the winner (the same prompt), else as
    :func:`result_probability`."""
    score = vote.scores[vote.groups[0][0]] if vote.scores else None
    if score is not None:
        return math.exp(score)
    return result_probability(translator, vote.result, shots, grammar_in_prompt)


def doubt_warning(stl: str, probability: float,
                  others: Sequence[tuple[str, float]] = ()) -> str:
    """What to tell a user whose answer the model doubts, with the answer read back, and
    ``others``' readings under it (formula, probability), as
    :func:`~ara.eval.translate.repair.readings` gives them after the winner."""
    lines = [f"note: the model gives this answer a probability of {probability:.2g}; below "
             f"{DOUBT:g}, many of its answers on held-out sentences are wrong. It "
             f"reads: \"{explain(parse(stl))}\". If that is not what you meant, reword the "
             "sentence" + (", or take one of the other readings it weighed:" if others
                           else ".")]
    lines += [f"  {other}  (probability {p:.2g}): \"{explain(parse(other))}\""
              for other, p in others]
    return "\n".join(lines)
