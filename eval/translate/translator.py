"""NL -> STL: prompt a backend, optionally under the request's grammar, parse the answer.

Validity under the constraint is a guarantee, not a statistic. The decoding grammar
is the canonical layout bounded in depth and width, so its language is finite and no
string is longer than ``max_length()`` characters. The token budget is that length
(every grammar token spends at least one character), so generation always ends in a
complete formula, and :meth:`Syntax.check` is then asserted on it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from functools import lru_cache

from ara.errors import AraError, ConfigError, STLSyntaxError
from ara.eval.translate.backends.base import Backend, BackendError, Sampling
from ara.eval.translate.prompt import (
    ANSWER_PREFIX,
    STOP,
    Shot,
    build_prompt,
    grammar_for_prompt,
    prompt_sha256,
)
from ara.eval.translate.request import Request
from ara.grammars import (
    BuiltGrammar,
    Formula,
    Syntax,
    build_grammar,
    parse,
    require_literals,
    to_text,
)
from ara.grammars.syntax import DECODING_MAX_ARGS, DECODING_MAX_DEPTH


@dataclass(frozen=True)
class TranslatorConfig:
    """How requests become grammars and prompts.

    Args:
        max_depth: Nesting depth the constrained grammar allows (default
            :data:`~ara.grammars.syntax.DECODING_MAX_DEPTH`, the training data's).
        max_args: Arguments of one & or | the constrained grammar allows (default
            :data:`~ara.grammars.syntax.DECODING_MAX_ARGS`, which loses nothing).
        intervals: Whether formulas may carry time intervals. On by default: a user
            should not have to know whether a sentence has a time bound, and an
            untimed sentence still comes out untimed.
        max_bound: Largest interval bound, with ``intervals``.
        bounds_from_request: With ``intervals``: an interval may only use 0 and the
            numbers the instruction writes (digits or words up to "hundred"), and a
            sentence with no number gets no interval at all. A reference formula
            whose bounds its sentence never writes is a rare noisy row, and the
            grammar stays a few rules instead of two per number up to ``max_bound``.
            Off: any number up to ``max_bound``.
        max_tokens: Budget for unconstrained answers.
    """

    max_depth: int = DECODING_MAX_DEPTH
    max_args: int = DECODING_MAX_ARGS
    intervals: bool = True
    max_bound: int = 1000
    bounds_from_request: bool = True
    max_tokens: int = 96

    def __post_init__(self) -> None:
        if self.max_depth < 1 or self.max_args < 2 or self.max_tokens < 1 or self.max_bound < 0:
            raise ConfigError(
                f"need max_depth >= 1, max_args >= 2, max_tokens >= 1, max_bound >= 0; got "
                f"{self.max_depth}, {self.max_args}, {self.max_tokens}, {self.max_bound}"
            )

    def syntax(self, aps: Sequence[str], nl: str | None = None) -> Syntax:
        """The language of one request: its propositions, and with ``nl`` under
        ``bounds_from_request``, the numbers it writes (:attr:`Request.numbers`)."""
        intervals, bounds = self.intervals, None
        if intervals and self.bounds_from_request and nl is not None:
            numbers = {n for n in Request.of(nl, aps).numbers if n <= self.max_bound}
            intervals, bounds = bool(numbers), (tuple(numbers | {0}) if numbers else None)
        return Syntax(aps=tuple(aps), intervals=intervals, max_bound=self.max_bound,
                      bounds=bounds, max_depth=self.max_depth, max_args=self.max_args)


@dataclass(frozen=True)
class TranslationResult:
    """One translation.

    Attributes:
        nl: The instruction.
        aps: Its atomic propositions.
        raw: The model's text.
        stl: Canonical formula, or ``None`` if the text does not parse.
        valid: Whether ``raw`` parses as STL.
        error: The parse error, if any.
        constrained: Whether decoding was grammar-constrained.
        grammar_in_prompt: Whether the prompt showed the grammar.
        shots: Number of worked examples in the prompt.
        prompt_sha256: Short hash of the exact prompt.
        prompt_tokens, completion_tokens, cached_tokens: Token counts.
        ms: Wall time of the backend call.
        stop: Why generation ended (``eos``, ``stop``, ``length``).
        masked_steps: Steps where the grammar overruled the model's first choice.
        grammar: Provenance of the decoding grammar (version, hash), if constrained.
        logprob: The model's log-probability of the answer, as :meth:`Translator.score`
            gives it, where decoding wrote the formula's canonical text in the
            tokenizer's own tokens (nearly always); else ``None``: score it.
    """

    nl: str
    aps: tuple[str, ...]
    raw: str
    stl: str | None
    valid: bool
    error: str | None
    constrained: bool
    grammar_in_prompt: bool
    shots: int
    prompt_sha256: str
    prompt_tokens: int
    completion_tokens: int
    cached_tokens: int
    ms: float
    stop: str
    masked_steps: int
    grammar: dict = field(default_factory=dict)
    logprob: float | None = None

    def to_dict(self) -> dict:
        data = asdict(self)
        data["aps"] = list(self.aps)
        return data


class RequestError(AraError, ValueError):
    """An instruction that cannot be translated as asked (empty, about propositions it
    never mentions, or with a bound the grammar cannot write)."""


def check_request(nl: str, aps: Sequence[str], config: TranslatorConfig) -> None:
    """Refuse a request a user most likely got wrong, saying what to change.

    Raises:
        RequestError: If ``nl`` is blank, no proposition is given, one is never
            mentioned, or a number in ``nl`` is above the grammar's largest bound.
        ConfigError: If a proposition is not a valid name.
    """
    if not nl.strip():
        raise RequestError("the instruction is empty: pass the sentence to translate, e.g. "
                           "'always avoid the door'")
    if not aps:
        raise RequestError("no propositions: name at least one in --aps, comma-separated "
                           "(e.g. go_to_kitchen,door_open)")
    Syntax(aps=tuple(aps))  # a bad name is refused here, before any model loads
    request = Request.of(nl, aps)
    unmentioned = request.unmentioned
    if unmentioned:
        raise RequestError(
            f"the instruction {nl!r} never mentions {', '.join(unmentioned)}: each proposition "
            "in --aps must be named in the sentence (by its name or a word of it, e.g. "
            "go_to_kitchen by 'kitchen'); drop the others from --aps")
    numbers = request.digits  # the grammar drops number words above its largest bound
    if config.intervals and numbers and max(numbers) > config.max_bound:
        raise RequestError(
            f"the instruction mentions {max(numbers)}, above the grammar's largest time bound "
            f"{config.max_bound}; pass --max-bound {max(numbers)} (Spot checks formulas up to "
            "1000) or rescale the time unit")


def admits(built: BuiltGrammar, raw: str) -> bool:
    """Whether ``raw`` (stop string removed) is what decoding under ``built`` may
    produce: the answer prefix and a formula of the language."""
    return raw.startswith(ANSWER_PREFIX) and built.syntax.accepts(raw[len(ANSWER_PREFIX):])


@lru_cache(maxsize=1024)
def decoding_grammar(built: BuiltGrammar) -> BuiltGrammar:
    """The grammar decoding runs under: the answer prefix, a formula of ``built``, and the
    newline that ends an answer (see :meth:`Grammar.with_suffix`)."""
    return BuiltGrammar(built.syntax,
                        built.grammar.with_prefix(ANSWER_PREFIX).with_suffix(STOP))


@lru_cache(maxsize=256)
def _requiring(built: BuiltGrammar, texts: tuple[str, ...]) -> BuiltGrammar:
    try:
        return BuiltGrammar(built.syntax, require_literals(built.grammar, texts))
    except ValueError as err:
        raise ConfigError(f"cannot require {', '.join(texts)} of this request: {err}") from None


class Translator:
    """Translate instructions with one backend.

    Args:
        backend: Any :class:`~ara.eval.translate.backends.base.Backend`.
        config: Grammar and budget settings.
    """

    def __init__(self, backend: Backend, config: TranslatorConfig | None = None) -> None:
        self.backend = backend
        self.config = config or TranslatorConfig()

    def grammar(self, aps: Sequence[str], nl: str | None = None) -> BuiltGrammar:
        """The request's grammar (see :meth:`TranslatorConfig.syntax`)."""
        return build_grammar(self.config.syntax(aps, nl))

    def translate(self, nl: str, aps: Sequence[str], shots: Sequence[Shot] = (),
                  grammar_in_prompt: bool = False, constrained: bool = True,
                  sampling: Sampling | None = None,
                  require: Sequence[str] = ()) -> TranslationResult:
        """Translate ``nl`` over the propositions ``aps``.

        Args:
            nl: The instruction.
            aps: Its atomic propositions (the grammar admits exactly these).
            shots: Worked examples for the prompt (variant F).
            grammar_in_prompt: Show the grammar in the prompt (variant P).
            constrained: Decode under the grammar (variant C).
            sampling: Draw the answer (seeded) instead of decoding greedily; see
                :mod:`ara.eval.translate.repair`.
            require: With ``constrained``: literals the answer must write, each a
                proposition of ``aps`` or a bound the grammar admits (e.g.
                ``("prop_3", "10")``); see :func:`~ara.grammars.require_literals`.

        Raises:
            ConfigError: If ``require`` names a literal the request's grammar never
                writes.
        """
        aps = tuple(aps)
        built = self.grammar(aps, nl)
        if require and constrained:
            built = _requiring(built, tuple(require))
        prompt = self._prompt(nl, aps, shots, grammar_in_prompt, built.syntax)
        if constrained:
            decoding = decoding_grammar(built)
            budget = int(decoding.grammar.max_length()) + 1
            completion = self.backend.complete(prompt, decoding, budget, STOP, sampling)
        else:
            completion = self.backend.complete(prompt, None, self.config.max_tokens, STOP,
                                               sampling)
        raw = completion.text
        if constrained and raw.endswith(STOP):  # the grammar's end marker, as free decoding
            raw = raw[: -len(STOP)]              # strips its stop string
        stl, error = None, None
        try:
            stl = to_text(parse(raw))
        except STLSyntaxError as err:
            error = str(err).splitlines()[0]
        if constrained:
            self._check_guarantee(built, raw, completion.stop)
        return TranslationResult(
            nl=nl, aps=aps, raw=raw, stl=stl, valid=stl is not None, error=error,
            constrained=constrained, grammar_in_prompt=grammar_in_prompt, shots=len(shots),
            prompt_sha256=prompt_sha256(prompt), prompt_tokens=completion.prompt_tokens,
            completion_tokens=completion.completion_tokens,
            cached_tokens=completion.cached_tokens, ms=completion.ms, stop=completion.stop,
            masked_steps=completion.masked_steps,
            grammar=built.provenance() if constrained else {},
            # what scoring feeds: the canonical text, then the end of the answer
            logprob=(completion.logprob if stl is not None and completion.text
                     == ANSWER_PREFIX + stl + STOP else None),
        )

    @property
    def can_score(self) -> bool:
        """Whether the backend can score answers (the local ones can; an HTTP server
        cannot)."""
        return callable(getattr(self.backend, "score", None))

    def score(self, nl: str, aps: Sequence[str], formulas: Sequence[Formula],
              shots: Sequence[Shot] = (), grammar_in_prompt: bool = False) -> list[float]:
        """The model's log-probability of each formula as the answer to ``nl``, written
        as decoding would write it (canonical text, then the end of the answer).

        Raises:
            BackendError: If the backend cannot score (an HTTP server).
        """
        if not self.can_score:
            raise BackendError(f"{type(self.backend).__name__} cannot score answers; "
                               "use a local model (llama.cpp or transformers)")
        prompt = self._prompt(nl, tuple(aps), shots, grammar_in_prompt,
                              self.grammar(aps, nl).syntax)
        return self.backend.score(prompt, [ANSWER_PREFIX + to_text(f) + STOP for f in formulas])

    @staticmethod
    def _prompt(nl: str, aps: tuple[str, ...], shots: Sequence[Shot], grammar_in_prompt: bool,
                syntax: Syntax) -> str:
        """The prompt both translating and scoring see, so that a score is of the answer
        to the very prompt a translation answered."""
        return build_prompt(nl, aps, shots, grammar_for_prompt(syntax) if grammar_in_prompt
                            else None)

    @staticmethod
    def _check_guarantee(built: BuiltGrammar, raw: str, stop: str) -> None:
        """A constrained answer is ' ' + a string of the language; anything else is a bug."""
        if not admits(built, raw):
            raise AssertionError(
                f"constrained decoding produced {raw!r} (stop={stop}), which the grammar does "
                "not admit; this is a bug in the backend's constraint, please report it"
            )

