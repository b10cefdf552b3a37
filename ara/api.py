"""The toolkit from Python, as its command line has it.

    >>> import ara
    >>> answer = ara.translate("Never enter the server room.", ["enter_server_room"])
    >>> answer.stl
    'G(!enter_server_room)'
    >>> ara.explain("G(battery_low -> F[0,30](at_charger))")
    'whenever battery_low, at_charger within 30 steps'
    >>> ara.equivalent("G(!(a | b))", "G(!a) & G(!b)")
    True

:func:`translate` returns an :class:`~ara.eval.translate.answering.Answer` (the formula, its
confidence, the other readings where the model doubts, what it leaves out of the
request; ``answer.to_json()`` is what ``ara translate --json`` prints) and keeps the
model loaded between calls. For finer control use the parts
it is made of: :class:`ara.eval.translate.translator.Translator`,
:func:`ara.eval.translate.answering.answer`, :mod:`ara.grammars`.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache
from typing import TYPE_CHECKING

from ara.grammars import parse

if TYPE_CHECKING:  # the model's modules load on first use
    from ara.eval.translate.answering import Answer


def translate(nl: str, aps: Sequence[str], model: str = "finetuned", *,
              shots: int | None = None, seed: int = 0, intervals: bool = True,
              max_bound: int = 1000, any_bound: bool = False, server: str = "auto",
              examples_by: str = "random", examples: str | None = None, **how) -> Answer:
    """Translate one instruction into STL over ``aps``, as ``ara translate`` does.

    Args:
        nl: The instruction, e.g. ``"always avoid the door"``.
        aps: Its atomic propositions, each named in the sentence.
        model, shots, seed, intervals, max_bound, any_bound, server: As the command's
            options of the same names (``model``: ``finetuned``, ``default``,
            ``lora:FILE``, a GGUF path, ``hf:FOLDER`` or an ``http(s)://`` endpoint).
        examples_by, examples: How the ``shots`` worked examples are chosen (``random``
            or ``similar`` to ``nl``) and from which file of pairs (``None``: the
            training mixture), as ``--examples-by`` and ``--examples``.
        **how: ``ara translate``'s other options, as :meth:`AnswerConfig.of
            <ara.eval.translate.answering.AnswerConfig.of>` names them (``repair``, ``repair_by``,
            ``samples``, ``doubt``, ``alternatives``, ``budget_s``: seconds for the whole
            answer, ``--budget``, ...).

    Returns:
        The answer: ``stl`` (``None`` if the model wrote no formula), ``confidence``,
        ``alternatives``, ``gaps``, ``result`` (the raw text, timings), ...

    Raises:
        ara.errors.AraError: On a request ``ara translate`` refuses (an empty
            instruction, a proposition the sentence never mentions, a bound above
            ``max_bound``) or a bad option.
    """
    from ara.eval.translate.answering import AnswerConfig, answer, worked_examples
    from ara.eval.translate.translator import TranslatorConfig, check_request

    aps = tuple(aps)
    config = TranslatorConfig(intervals=intervals, max_bound=max_bound,
                              bounds_from_request=not any_bound)
    check_request(nl, aps, config)
    # Options and worked examples first: a mistake there is refused before the model loads.
    how = AnswerConfig.of(seed=seed, **how)
    shown = worked_examples(model, shots, aps, seed, nl, examples_by, examples)
    return answer(translator(model, config, server), nl, aps, shown, how)


@lru_cache(maxsize=4)
def translator(model: str = "finetuned", config=None, server: str = "auto"):
    """The :class:`~ara.eval.translate.translator.Translator` for ``model`` and ``config`` (a
    :class:`~ara.eval.translate.translator.TranslatorConfig`), loaded once and kept: loading the
    embedded model takes seconds, a translation a fraction of one. Translators of one
    model with other configs share its backend
    (:func:`~ara.eval.translate.models.shared_backend`)."""
    from ara.eval.translate.models import shared_backend
    from ara.eval.translate.translator import Translator

    return Translator(shared_backend(model, server=server), config)


def explain(formula: str) -> str:
    """A deterministic plain-English reading of ``formula`` (``ara stl explain``)."""
    from ara.grammars.english import explain as read

    return read(parse(formula))


def equivalent(a: str, b: str, timeout_s: float | None = 10.0) -> bool:
    """Whether formulas ``a`` and ``b`` hold on exactly the same traces, decided by
    Spot (``ara stl equiv``).

    Raises:
        ara.grammars.spot_bridge.SpotTimeoutError: If Spot takes over ``timeout_s``.
    """
    from ara.grammars.spot_bridge import equivalent as same

    return same(parse(a), parse(b), timeout_s=timeout_s)
