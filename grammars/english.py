"""STL in plain English: one realizer for reading a formula back and for writing
varied training sentences.

``explain(formula)`` is deterministic: the first phrasing of every construct, steps as
the unit, propositions by name. ``realize(formula, rng, ...)`` draws a phrasing per
construct, a time unit and a sentence layout, so one formula becomes many sentences.

Idioms come before composition: ``G(!a)`` reads "never a", ``G(F(a))`` "a infinitely
often", ``G(a -> F(b))`` "whenever a, eventually b", ``G(F[0,n](a))`` "a at least once
every n steps", ``F[0,n](G(a))`` "within n steps, a for good", ``G(!a -> b)`` "b
unless a", ``F(a & F(b))`` "first a, then b",
``G(a -> G(b))`` "once a, b from then on",
``F(a & F[0,n](b))`` "a, and within n steps after that, b", ``!a U b`` "do not a until
b", ``F(a & G(b))`` "eventually a, and from then on always b", ``(a | b) & !(a & b)`` "a
or b, but not both"; in sampled sentences also ``F(a) & F(b)`` "a and b, in any order",
``G(a -> F(b))`` with ``b`` a command "whenever a, b", and over places ``F(G(a))`` "go
to a and stay there", ``G(F(a))`` "keep coming back to a", ``G(F(a)) & G(F(b))``
"patrol between a and b"; and ``G(a -> !b)`` with ``b`` an action "never b while a".
Everything else is read compositionally, and a binary subformula under another
operator is read in its bracketing form ("both ... and ...", "either ... or ...") so
that the scope survives in the sentence.

A few phrasings per construct are *held out* (:data:`HELD_OUT`): the compositional
test split uses them and training never does, to measure whether a translator
generalizes to wordings it never saw.
"""

from __future__ import annotations

import random
from collections.abc import Callable
from dataclasses import dataclass, field

from ara.errors import ConfigError
from ara.grammars.ast import (
    Always,
    And,
    Atom,
    Const,
    Eventually,
    Formula,
    Iff,
    Implies,
    Interval,
    Next,
    Not,
    Or,
    Until,
    conjuncts,
    is_temporal,
    walk,
)

# {a}, {b}: operands; {n}: an upper bound from 0; {lo}, {hi}: a window; {u}: the unit,
# plural ("steps"); {s}: the unit, singular, only for step-like units ("step 5").
PHRASES: dict[str, tuple[str, ...]] = {
    "F": ("eventually {a}", "at some point {a}", "{a} at some point", "sometime {a}",
          "{a} eventually", "make sure that eventually {a}", "sooner or later {a}",
          "finally {a}", "at some moment in the future {a}"),
    # F over an action said as a command: "go to the kitchen" asks for it at some point.
    "F_do": ("{a}", "make sure to {a}", "{a} at some point", "you have to {a}",
             "please {a}", "{a} eventually", "at some point you should {a}",
             "you need to {a}"),
    "F_n": ("within {n} {u}, {a}", "{a} within {n} {u}", "in the next {n} {u}, {a}",
            "{a} within the next {n} {u}", "no later than {s} {n}, {a}",
            "{a} in at most {n} {u}", "before {n} {u} have passed, {a}",
            "at some point in the next {n} {u}, {a}", "{a} at some point within {n} {u}",
            "{a} at least once in the next {n} {u}"),
    "F_ab": ("at some point between {s} {lo} and {s} {hi}, {a}",
             "{a} between {lo} and {hi} {u} from now", "within {lo} to {hi} {u}, {a}",
             "{a} sometime from {s} {lo} to {s} {hi}",
             "after {lo} {u} but no later than {hi} {u}, {a}",
             "at some time in the window from {lo} to {hi} {u}, {a}",
             "between {s} {lo} and {s} {hi}, {a} at least once",
             "{a} at least once between {lo} and {hi} {u} from now",
             "no sooner than {s} {lo} and no later than {s} {hi}, {a}",
             "{a} no earlier than {lo} {u} and no later than {hi} {u} from now",
             "{a} no sooner than {s} {lo} and no later than {s} {hi}"),
    "G": ("always {a}", "{a} at all times", "at every step, {a}", "{a} forever",
          "it is always the case that {a}", "globally {a}", "{a} all the time",
          "constantly {a}", "{a} the whole time"),
    "G_n": ("for the first {n} {u}, {a}", "{a} for the next {n} {u}",
            "during the first {n} {u}, {a}", "{a} at every step until {s} {n}",
            "for {n} {u}, {a}", "{a} continuously for {n} {u}"),
    "G_ab": ("from {s} {lo} to {s} {hi}, {a}", "{a} at every step between {lo} and {hi} {u}",
             "throughout the window from {lo} to {hi} {u}, {a}",
             "{a} all the time from {lo} to {hi} {u}",
             "for each time instant in the next {lo} to {hi} {u}, {a}",
             "between {s} {lo} and {s} {hi}, {a} the whole time",
             "{a} from {s} {lo} through {s} {hi}"),
    "never": ("never {a}", "at no time {a}", "{a} must never happen", "must not ever {a}",
              "always avoid {a}", "avoid {a} at all times", "it must never be the case that {a}",
              "under no circumstances {a}", "{a} is never allowed"),
    "never_n": ("never {a} in the first {n} {u}", "do not {a} during the first {n} {u}",
                "avoid {a} for the next {n} {u}", "at no time in the next {n} {u}, {a}",
                "{a} must not happen within {n} {u}"),
    "never_ab": ("never {a} between {s} {lo} and {s} {hi}", "avoid {a} from {lo} to {hi} {u}",
                 "at no time between {lo} and {hi} {u}, {a}"),
    "FG": ("eventually {a} forever", "eventually always {a}", "from some point on, always {a}",
           "sooner or later {a} for good", "{a} eventually holds forever",
           "{a} from some point on, forever", "eventually {a} and from then on it stays so",
           "in the end, {a} permanently"),
    # F[..](G(a)): said with words that last, since "within 5 steps, globally a" reads
    # as a G bounded by 5 steps as much as a moment by which a starts to hold for good.
    "FG_n": ("within {n} {u}, {a} for good", "{a} within {n} {u}, and from then on forever",
             "no later than {s} {n}, {a}, and it stays so from then on",
             "in the next {n} {u}, {a} from some point on, forever",
             "{a} within the next {n} {u} and permanently after that",
             "within {n} {u}, {a}, and from then on that holds for good"),
    "FG_ab": ("at some point between {s} {lo} and {s} {hi}, {a} for good",
              "{a} between {lo} and {hi} {u} from now, and from then on forever",
              "no sooner than {s} {lo} and no later than {s} {hi}, {a}, and it stays so "
              "from then on",
              "within {lo} to {hi} {u}, {a} permanently",
              "after {lo} {u} but no later than {hi} {u}, {a} for good",
              "between {lo} and {hi} {u} from now, {a}, and from then on that holds for good"),
    # F(G(a)) and G(F(a)) over a place: where the robot ends up, where it keeps going.
    "FG_place": ("go to {x} and stay there", "reach {x} and remain there",
                 "get to {x} and stay there for good", "head to {x} and remain there forever",
                 "end up at {x} and never leave"),
    "GF": ("{a} infinitely often", "{a} over and over again", "repeatedly {a}",
           "always eventually {a}", "{a} again and again", "keep returning to {a} forever",
           "{a} periodically", "regularly {a}", "{a} time and again"),
    # G(F[0,n](a)): a recurrence with a longest gap.
    "GF_n": ("{a} at least once every {n} {u}", "at least once every {n} {u}, {a}",
             "{a} at least every {n} {u}", "{a} regularly, at most {n} {u} apart",
             "{a} every {n} {u} or more often"),
    "GF_place": ("keep coming back to {x}", "return to {x} again and again",
                 "keep visiting {x} forever", "visit {x} over and over",
                 "go back to {x} infinitely often"),
    # G(F(a)) & G(F(b)) over two places: a patrol.
    "GF2_place": ("patrol between {x} and {y}", "go back and forth between {x} and {y} forever",
                  "keep visiting {x} and {y}", "keep coming back to {x} and to {y}",
                  "alternate between {x} and {y} forever"),
    # F(a & G(b)): a moment, and what holds from it on.
    "F_then_G": ("eventually {a}, and from then on always {b}",
                 "at some point {a}, and from that moment on {b} forever",
                 "{a} at some point, and after that {b} at all times",
                 "sooner or later {a}, and from then on {b} holds forever",
                 "eventually {a}; from that point on, always {b}"),
    # F(a & G[0,n](a)): a state reached and kept a while, said of a condition, of a
    # lasting action ("hold the box for 5 minutes at some point") or of a place ("fly to
    # waypoint 3 and hover there for 15 seconds").
    "F_stay_n": ("eventually {a}, and it stays so for {n} {u}",
                 "at some point {a}, and that holds for the next {n} {u}",
                 "{a} at some point, and for {n} {u} from then on",
                 "sooner or later {a}, for at least {n} {u}"),
    "F_stay_n_do": ("{a} for {n} {u} at some point", "at some point {a}, and keep doing so "
                    "for {n} {u}", "sooner or later {a} for {n} {u} straight",
                    "{a} for at least {n} {u} at some point"),
    "F_stay_n_place": ("go to {x} and stay there for {n} {u}",
                       "reach {x} and remain there for {n} {u}",
                       "get to {x} and wait there for {n} {u}",
                       "head to {x}, then stay there for {n} {u}",
                       "go to {x} and hold position there for {n} {u}"),
    # (!b U a) & F(b): b at some point, never before a (Dwyer et al.'s precedence,
    # !b W a, with b required to happen).
    "precedence": ("{b}, but only after {a}", "{b}, but not before {a}",
                   "only after {a}, {b}", "{a}, and only after that {b}",
                   "{b} at some point, never before {a}",
                   "{a} first; only then {b}", "first {a}, and only then {b}"),
    # (a | b) & !(a & b)
    "xor": ("{a} or {b}, but not both", "either {a} or {b}, but not both",
            "exactly one of {a} and {b}", "{a} or {b}, never both",
            "{a} or {b}, but not the two together"),
    "response": ("whenever {a}, eventually {b}", "every time {a}, {b} at some later point",
                 "each time {a}, make sure that eventually {b}", "if ever {a}, then eventually {b}",
                 "{a} is always followed by {b}", "any time {a}, sooner or later {b}",
                 "if {a}, eventually {b}", "when {a}, {b} at some point after that"),
    # Response with a command said on its own: "whenever the battery is low, go to the
    # charging station" asks for it some time after, as a bare command at the top does.
    "response_do": ("whenever {a}, {b}", "every time {a}, {b}", "each time {a}, {b} afterwards",
                    "if ever {a}, {b} at some point after that", "{b} every time {a}",
                    "if {a}, {b}", "when {a}, {b}"),
    "response_n": ("whenever {a}, {b} within {n} {u}",
                   "every time {a}, {b} within the next {n} {u}",
                   "each time {a}, {b} in at most {n} {u}",
                   "whenever {a}, within {n} {u} {b}",
                   "if {a}, {b} within {n} {u}", "when {a}, {b} within {n} {u}",
                   "if {a}, {b} in at most {n} {u}"),
    # G(a -> !b) with b an action: what is forbidden while a holds.
    "invariant_not": ("never {b} while {a}", "do not {b} while {a}", "never {b} when {a}",
                      "you must not {b} while {a}", "{b} is not allowed while {a}",
                      "whenever {a}, never {b}"),
    # G(!a -> b): what holds except while a condition does.
    "unless": ("{b} unless {a}", "always {b} unless {a}", "unless {a}, {b}",
               "{b} at all times, except while {a}", "at all times, {b} unless {a}",
               "{b}, except when {a}"),
    "invariant": ("whenever {a}, {b}", "every time {a}, also {b}", "{b} whenever {a}",
                  "at all times, if {a} then {b}", "always, if {a}, then {b}",
                  "while {a}, {b}", "{b} while {a}", "as long as {a}, {b}",
                  "{b} as long as {a}", "{a} only when {b}", "{a} only while {b}",
                  "if {a}, {b}", "when {a}, {b}"),
    # G(a -> G(b)): from the moment a holds, b for good.
    "once_always": ("once {a}, {b} from then on", "after {a}, {b} forever",
                    "once {a}, always {b} after that", "if ever {a}, {b} from then on",
                    "from the moment {a}, {b} for good"),
    "once_never": ("once {a}, never {b} again", "after {a}, never {b} again",
                   "once {a}, do not {b} ever again", "if ever {a}, never {b} after that"),
    "sequence": ("first {a}, then {b}", "{a} and after that {b}", "{a}, and afterwards {b}",
                 "{a} and then {b}", "eventually {a} and later {b}", "{a}, followed by {b}",
                 "{a}, then {b}", "{a} first, and {b} afterwards", "after {a}, {b}",
                 "{a}; once that is done, {b}", "{a} and {b}, in that order"),
    # F(a & F[0,n](b)): the second step has a deadline counted from the first.
    "sequence_n": ("{a}, and within {n} {u} after that, {b}", "first {a}, then {b} within {n} {u}",
                   "{a}, then within {n} {u} {b}", "after {a}, {b} within {n} {u}",
                   "{a}, and no more than {n} {u} later, {b}"),
    "sequence3": ("first {a}, then {b}, then {c}", "{a}, then {b}, and finally {c}",
                  "{a}, after that {b}, and after that {c}", "{a}, then {b}, then {c}",
                  "in this order: {a}, {b}, {c}", "{a}, {b}, and then {c}",
                  "first {a}, next {b}, and last {c}", "{a}, afterwards {b}, then {c}",
                  "{a}, {b} and {c}, in that order"),
    # F(a) & F(b) [& F(c)] at the top: each at some point, the order left open.
    "visit_any": ("{l}, in any order", "{l} in any order", "{l}, in whatever order",
                  "{l}, the order does not matter"),
    "avoid_until": ("do not {a} until {b}", "{a} must not happen before {b}",
                    "avoid {a} until {b}", "never {a} before {b}",
                    "wait until {b} before you {a}",
                    "{b} eventually, but do not {a} before that",
                    "eventually {b}, and never {a} before that"),
    "U": ("{a} until {b}", "keep {a} until {b}", "{a} holds until {b}",
          "{a} must hold until {b} happens", "continue {a} until {b}",
          "{a} up to the moment {b}"),
    "U_n": ("{a} until {b}, which must happen within {n} {u}",
            "keep {a} until {b} happens within {n} {u}", "{a} until {b} within the next {n} {u}"),
    "U_ab": ("{a} until {b} happens between {s} {lo} and {s} {hi}",
             "keep {a} until {b}, which happens within {lo} to {hi} {u}",
             "{a} until, between {lo} and {hi} {u} from now, {b}"),
    "->": ("if {a}, then {b}", "{a} implies {b}", "{b} if {a}", "in case {a}, {b}",
           "provided that {a}, {b}", "{a} means that {b}", "{a} only if {b}"),
    # A top-level a -> b over a condition a at the first instant, in words: "if the door
    # is open, ..." reads as a standing rule (G), as people write them.
    "->now": ("if {a} at the start, then {b}", "if initially {a}, then {b}",
              "{a} at the start implies {b}", "if right now {a}, then {b}",
              "in case {a} at the outset, {b}"),
    "<->": ("{a} if and only if {b}", "{a} exactly when {b}", "{a} is equivalent to {b}",
            "{a} precisely when {b}", "{a} when and only when {b}",
            "{a}, if and only if {b}"),
    "&": ("{a} and {b}", "{a}, and also {b}", "{a} as well as {b}", "{a}, and {b}"),
    "|": ("{a} or {b}", "{a}, or else {b}", "{a} or alternatively {b}", "{a}, or {b}"),
    "!": ("not {a}", "it is not the case that {a}", "{a} does not hold"),
    "!act": ("do not {a}", "don't {a}"),
    # Bracketing forms: a binary subformula under another operator. The plain ones
    # ("always a or b" for G(a | b), as people say it) only over propositions: see
    # _say for why that reading is never given to G(a) | b.
    "&()": ("both {a} and {b}", "{a} and at the same time {b}", "{a} and {b}",
            "{a} and {b} at the same time"),
    "|()": ("either {a} or {b}", "at least one of {a} or {b}", "{a} or {b}"),
    "->()": ("if {a} then {b}",),
    "->now()": ("if initially {a} then {b}", "if right now {a} then {b}"),
    "<->()": ("{a} exactly when {b}", "{a} if and only if {b}"),
    "U()": ("{a} until {b}",),
    "true": ("true",),
    "false": ("false",),
}

#: Phrasings only the compositional test split uses; training never sees them.
HELD_OUT: dict[str, frozenset[str]] = {
    "F": frozenset({"at some moment in the future {a}"}),
    "F_stay_n_place": frozenset({"head to {x}, then stay there for {n} {u}"}),
    "precedence": frozenset({"{a} first; only then {b}"}),
    "F_do": frozenset({"you need to {a}"}),
    "F_n": frozenset({"before {n} {u} have passed, {a}"}),
    "F_ab": frozenset({"at some time in the window from {lo} to {hi} {u}, {a}"}),
    "G": frozenset({"constantly {a}"}),
    "G_n": frozenset({"{a} continuously for {n} {u}"}),
    "G_ab": frozenset({"{a} all the time from {lo} to {hi} {u}"}),
    "never": frozenset({"under no circumstances {a}"}),
    "never_n": frozenset({"{a} must not happen within {n} {u}"}),
    "FG": frozenset({"{a} from some point on, forever"}),
    "FG_n": frozenset({"{a} within the next {n} {u} and permanently after that"}),
    "FG_ab": frozenset({"{a} between {lo} and {hi} {u} from now, and from then on forever"}),
    "GF": frozenset({"keep returning to {a} forever"}),
    "GF_n": frozenset({"{a} every {n} {u} or more often"}),
    "unless": frozenset({"{b}, except when {a}"}),
    "response": frozenset({"any time {a}, sooner or later {b}"}),
    "response_do": frozenset({"{b} every time {a}"}),
    "response_n": frozenset({"whenever {a}, within {n} {u} {b}"}),
    "invariant": frozenset({"always, if {a}, then {b}"}),
    "invariant_not": frozenset({"{b} is not allowed while {a}"}),
    "once_always": frozenset({"from the moment {a}, {b} for good"}),
    "once_never": frozenset({"once {a}, do not {b} ever again"}),
    "->now": frozenset({"in case {a} at the outset, {b}"}),
    "sequence": frozenset({"{a}, followed by {b}"}),
    "sequence_n": frozenset({"{a}, and no more than {n} {u} later, {b}"}),
    "sequence3": frozenset({"in this order: {a}, {b}, {c}"}),
    "visit_any": frozenset({"{l}, the order does not matter"}),
    "U": frozenset({"continue {a} until {b}"}),
    "<->": frozenset({"{a} when and only when {b}"}),
    "|": frozenset({"{a}, or {b}"}),
    "FG_place": frozenset({"end up at {x} and never leave"}),
    "GF_place": frozenset({"go back to {x} infinitely often"}),
    "GF2_place": frozenset({"alternate between {x} and {y} forever"}),
    "F_then_G": frozenset({"eventually {a}; from that point on, always {b}"}),
    "xor": frozenset({"{a} or {b}, but not the two together"}),
}

#: Time units: (plural, singular or None where "step 5" would not read).
UNITS: tuple[tuple[str, str | None], ...] = (
    ("steps", "step"), ("time steps", "time step"), ("time units", None), ("seconds", None),
    ("minutes", "minute"), ("hours", "hour"),
)
MODES = ("all", "train", "test")
#: Said only of propositions in words: an "if"/"when" at the head of a standing rule is
#: how people write G(a -> ...), while NL2TL's lifted sentences (the paper split's) read
#: "if (prop_1), (prop_2)" at the first instant.
IN_WORDS_ONLY = frozenset({
    "if {a}, eventually {b}", "when {a}, {b} at some point after that", "if {a}, {b}",
    "when {a}, {b}", "if {a}, {b} within {n} {u}", "when {a}, {b} within {n} {u}",
    "if {a}, {b} in at most {n} {u}"})
#: Plain bracketing forms, said only when every operand is a proposition or its negation.
PLAIN = frozenset({"{a} and {b}", "{a} or {b}", "{a} and {b} at the same time"})
#: Commands said bare, as one side of a choice.
_BARE_DO = frozenset({"{a}", "{a} at some point", "{a} eventually"})


@dataclass(frozen=True)
class Realizer:
    """How one sentence is worded.

    Args:
        rng: Draws the phrasings; ``None`` takes the first phrasing everywhere.
        mode: ``train`` never uses held-out phrasings, ``test`` prefers them where a
            construct has one, ``all`` draws from every phrasing.
        unit: Index into :data:`UNITS`.
        say_atom: How a proposition is said (``prop_1`` -> ``(prop_1)``, or
            ``go_to_kitchen`` -> ``go to the kitchen``).
        is_action: Whether a proposition reads as an imperative ("do not go ...").
        is_lasting: Whether an action is a state while it lasts ("hold the box"):
            "whenever c, hold the box" asks for it then, so the response idiom
            ``G(c -> F(b))`` never says such a ``b`` as the bare command.
        say_negated: How ``!name`` is said where the language has a word for it
            ("stay out of the kitchen" for ``!in_kitchen``), else ``None``; used in
            sampled sentences only, half the time, under ``G`` and in invariants.
        say_place: The place a proposition is about ("the charging station" for
            ``at_charging_station``), else ``None``: ``F(G(a))`` may then be said "go to
            the charging station and stay there" and ``G(F(a))`` "keep coming back to
            it"; sampled sentences only, half the time.
        in_words: Whether propositions are said in words (a clause, a command) rather
            than by name: then ``a U b`` says ``a`` only before "until" ("the door is
            open until ...", not "keep the door is open until ...").
    """

    rng: random.Random | None = None
    mode: str = "all"
    unit: int = 0
    say_atom: Callable[[str], str] = field(default=lambda name: name)
    is_action: Callable[[str], bool] = field(default=lambda name: False)
    is_lasting: Callable[[str], bool] = field(default=lambda name: False)
    say_negated: Callable[[str], str | None] = field(default=lambda name: None)
    say_place: Callable[[str], str | None] = field(default=lambda name: None)
    in_words: bool = False

    def __post_init__(self) -> None:
        if self.mode not in MODES:
            raise ConfigError(f"realizer mode must be one of {MODES}, got {self.mode!r}")
        if not 0 <= self.unit < len(UNITS):
            raise ConfigError(f"unit must index UNITS (0..{len(UNITS) - 1}), got {self.unit}")

    def pick(self, construct: str, used: list[str] | None = None, first: int = 0,
             allow: Callable[[str], bool] | None = None, **slots: object) -> str:
        """One phrasing of ``construct`` with its slots filled, among those ``allow``
        admits; without an ``rng``, the one at index ``first``, or if ``allow`` refuses
        it, the first phrasing that ``allow`` admits."""
        plural, singular = UNITS[self.unit]
        options = [p for p in PHRASES[construct] if (singular is not None or "{s}" not in p)
                   and (allow is None or allow(p)) and (self.in_words or p not in IN_WORDS_ONLY)]
        held = HELD_OUT.get(construct, frozenset())
        if self.mode == "train":
            options = [p for p in options if p not in held] or options
        elif self.mode == "test" and self.rng is not None:
            preferred = [p for p in options if p in held]
            if preferred and self.rng.random() < 0.7:
                options = preferred
        if self.rng is None:
            phrase = PHRASES[construct][first]
            if allow is not None and not allow(phrase):
                phrase = next(p for p in PHRASES[construct] if allow(p))
        else:
            phrase = self.rng.choice(options)
        if used is not None:
            used.append(f"{construct}:{PHRASES[construct].index(phrase)}")
        return phrase.format(u=plural, s=singular, **slots)


def explain(formula: Formula) -> str:
    """A deterministic plain-English reading of ``formula``.

    >>> from ara.grammars import parse
    >>> explain(parse("G(a -> F[0,5](b))"))
    'whenever a, b within 5 steps'
    """
    return _say(formula, Realizer(say_atom=lambda name: name), None, embedded=False)


def realize(formula: Formula, realizer: Realizer, used: list[str] | None = None) -> str:
    """One wording of ``formula``; ``used`` collects the ids of the phrasings used."""
    text = _say(formula, realizer, used, embedded=False, now=True)
    rng = realizer.rng
    if rng is not None:
        # "Prop_1" would be another proposition: never capitalize a name
        if rng.random() < 0.5 and "_" not in text.split(" ", 1)[0]:
            text = text[0].upper() + text[1:]
        if rng.random() < 0.4:
            text += "."
    return text


def _say(f: Formula, r: Realizer, used: list[str] | None, embedded: bool,
         now: bool = False, plain: bool = True) -> str:
    """``now``: ``f`` is read at the first instant (outside every temporal operator),
    where a bare command ("go to the kitchen") means "at some point". ``plain``: a
    Boolean ``f`` may take a plain bracketing form; not under another ``&`` or ``|``,
    where "either a or b and c" would hide the scope."""
    visits = None if embedded or r.rng is None else _visits(f)
    if visits is not None and r.rng.random() < 0.5:
        said = [_say(g, r, used, embedded=True) for g in visits]
        listing = " and ".join(said) if len(said) == 2 else f"{', '.join(said[:-1])} and {said[-1]}"
        return r.pick("visit_any", used, l=listing)
    idiom = _idiom(f, r, used, now)
    if idiom is not None:
        return idiom

    def sub(g: Formula) -> str:
        return _say(g, r, used, embedded=True)

    def sub_now(g: Formula) -> str:
        return _say(g, r, used, embedded=True, now=now)

    if isinstance(f, Atom):
        return r.say_atom(f.name)
    if isinstance(f, Const):
        return r.pick("true" if f.value else "false", used)
    if isinstance(f, Not):
        act = isinstance(f.arg, Atom) and r.is_action(f.arg.name)
        return r.pick("!act" if act else "!", used, a=sub_now(f.arg))
    if isinstance(f, Next):
        return f"at the next step {sub(f.arg)}"
    if isinstance(f, Eventually) and now and f.interval is None and isinstance(f.arg, Atom) \
            and r.is_action(f.arg.name):
        return r.pick("F_do", used, a=sub(f.arg))
    if isinstance(f, (Eventually, Always)):
        op = "F" if isinstance(f, Eventually) else "G"
        allow = _said_first(f.arg) if op == "F" else None
        return _timed(op, f.interval, r, used, allow=allow, a=sub(f.arg))
    if isinstance(f, (And, Or)):
        op = "&" if isinstance(f, And) else "|"
        key = op + "()" if embedded else op
        plain = plain and all(_is_literal(g) for g in f.args)

        def operand(g: Formula) -> str:
            return _say(g, r, used, embedded=True, now=now, plain=False)

        text = operand(f.args[0])
        for left, arg in zip(f.args, f.args[1:], strict=False):
            # A comma keeps "first a, then b, and never c" from reading as one sequence.
            comma = 3 if not embedded and " " in text else 0
            allow = (lambda p: plain or p not in PLAIN) if embedded else _scoped(left, arg)
            text = r.pick(key, used, first=comma, allow=allow, a=text, b=operand(arg))
        return text
    if isinstance(f, Until):
        # A proposition said in words reads only before "until": not "keep hold the box
        # until ...", "the door is open holds until ...".
        allow = (lambda p: p.startswith(("{a} until", "{a} up to"))) if r.in_words else None
        if f.interval is None:
            return r.pick("U()" if embedded else "U", used, allow=allow, a=sub(f.lhs),
                          b=sub(f.rhs))
        return _timed("U", f.interval, r, used, allow=allow, a=sub(f.lhs), b=sub(f.rhs))
    op = "->" if isinstance(f, Implies) else "<->"
    if op == "->" and r.in_words and now and not is_temporal(f.lhs):
        op = "->now"  # "if the door is open, ..." would read as a standing rule
    if embedded:
        return r.pick(op + "()", used, a=sub_now(f.lhs), b=sub_now(f.rhs))
    scoped, only = _scoped(f.lhs, f.rhs), _only(f.lhs)
    return r.pick(op, used, allow=lambda p: (scoped is None or scoped(p)) and only(p),
                  a=sub_now(f.lhs), b=sub_now(f.rhs))


def _is_literal(f: Formula) -> bool:
    return isinstance(f, (Atom, Const)) or (isinstance(f, Not) and isinstance(f.arg, Atom))


def _scoped(lhs: Formula, rhs: Formula) -> Callable[[str], bool] | None:
    """Which phrasings of a top-level ``lhs op rhs`` keep ``op`` outside ``lhs``.

    "always a or b" is how people say ``G(a | b)`` (the plain bracketing form), so
    ``G(a) | b`` must not be said that way: when ``lhs`` is more than a proposition and
    ``rhs`` a proposition, a phrasing must set ``lhs`` off with a comma ("always a, or
    b") or not begin with it ("b if always a").
    """
    if _is_literal(lhs) or not _is_literal(rhs):
        return None
    return lambda p: p.startswith("{a},") or not p.startswith("{a}")


def _only(lhs: Formula) -> Callable[[str], bool]:
    """Whether a phrasing may be said: "a only if b" and "a only when b" only for a
    proposition ``a``, since after "p or q", "only if" would read as binding ``q`` alone."""
    return lambda p: _is_literal(lhs) or " only " not in p.replace("and only", "")


def _negated(f: Not, r: Realizer) -> str | None:
    """The word for ``!name`` ("stay out of the kitchen"), in half the sampled
    sentences where there is one. Said only where ``!name`` holds throughout (under
    ``G``, or what an invariant asks for): "eventually stay out of the kitchen" would
    read as F(G(!in_kitchen)), not F(!in_kitchen)."""
    return _sometimes(f.arg, r.say_negated, r)


def _sometimes(f: Formula, say: Callable[[str], str | None], r: Realizer) -> str | None:
    """``say``'s words for the proposition ``f``, in half the sampled sentences where
    it has some, else ``None``."""
    if r.rng is None or not isinstance(f, Atom):
        return None
    said = say(f.name)
    return said if said is not None and r.rng.random() < 0.5 else None


def _timed(op: str, interval: Interval | None, r: Realizer, used: list[str] | None,
           allow: Callable[[str], bool] | None = None, **slots: str) -> str:
    """An operator with its interval: untimed, ``[0,n]`` or a window ``[lo,hi]``."""
    if interval is None:
        return r.pick(op, used, allow=allow, **slots)
    if interval.hi is None:  # [lo,inf]: no construct of its own; say the lower bound
        return r.pick(op, used, allow=allow, **slots) + f" (from step {interval.lo} on)"
    if interval.lo == 0:
        return r.pick(op + "_n", used, allow=allow, n=interval.hi, **slots)
    return r.pick(op + "_ab", used, allow=allow, lo=interval.lo, hi=interval.hi, **slots)


def _said_first(operand: Formula) -> Callable[[str], bool] | None:
    """Which phrasings of an ``F`` may say ``operand`` first: not a negation, since "do
    not go to the kitchen within 5 steps" reads as never going there in that time, nor
    an implication, since "if a then b eventually" reads as a rule, ``G(a -> F(b))``."""
    if not isinstance(operand, (Not, Implies, Iff)):
        return None
    return lambda p: not p.startswith("{a}")


def _untimed(f: Formula, op: type) -> Formula | None:
    """The argument of an untimed ``op`` (``Eventually``, ``Always``), else ``None``."""
    return f.arg if isinstance(f, op) and f.interval is None else None


def _idiom(f: Formula, r: Realizer, used: list[str] | None, now: bool = False) -> str | None:
    """The idiomatic reading of a common pattern, or ``None``."""

    def sub(g: Formula) -> str:
        return _say(g, r, used, embedded=True)

    if isinstance(f, Always) and isinstance(f.arg, Not) and (
            f.interval is None or f.interval.hi is not None):
        negated = _negated(f.arg, r)
        if negated is not None:  # "always stay out of the kitchen"
            return _timed("G", f.interval, r, used, a=negated)
        return _timed("never", f.interval, r, used, a=sub(f.arg.arg))
    gap = _untimed(f, Always)
    if isinstance(gap, Eventually) and gap.interval is not None and gap.interval.lo == 0 \
            and gap.interval.hi is not None:
        # "at least once every 6 steps"
        return r.pick("GF_n", used, a=sub(gap.arg), n=gap.interval.hi)
    if isinstance(f, Eventually) and f.interval is not None and f.interval.hi is not None \
            and _untimed(f.arg, Always) is not None \
            and (not is_temporal(f.arg.arg) or isinstance(f.arg.arg, Until)):
        # "within 5 steps, the gate is closed for good"; over an until too, since
        # "within 31 hours, globally a until b" has no word that lasts
        kept = f.arg.arg
        # An until is set off by commas: "within 31 hours, a until b for good" reads as
        # a U G(b), and "a until b within 31 hours, ..." as a bounded until
        allow = (lambda p: ", {a}, and" in p) if isinstance(kept, Until) else _said_first(kept)
        return _timed("FG", f.interval, r, used, allow=allow, a=sub(kept))
    for outer, nested, key in ((Eventually, Always, "FG"), (Always, Eventually, "GF")):
        inner = _untimed(f, outer)
        if inner is not None and _untimed(inner, nested) is not None:
            # "go to the dock and stay there", "keep coming back to the dock"
            place = _sometimes(inner.arg, r.say_place, r)
            if place is not None:
                return r.pick(key + "_place", used, x=place)
            return r.pick(key, used, a=sub(inner.arg))
    stay = held_for(f)
    if stay is not None:
        # "fly to waypoint 3 and hover there for 15 seconds"
        kept, n = stay
        place = _sometimes(kept, r.say_place, r)
        if place is not None:
            return r.pick("F_stay_n_place", used, x=place, n=n)
        command = isinstance(kept, Atom) and r.is_action(kept.name)
        return r.pick("F_stay_n_do" if command else "F_stay_n", used, a=sub(kept), n=n)
    if _is_precedence(f):
        # "connect the wires, and only after that screw on the cover"
        first = f.args[0].rhs
        # A command is not said after "after" or "before" ("only after connect the
        # wires" is no English): "connect the wires, and only after that ..."
        command = any(isinstance(g, Atom) and r.is_action(g.name) for g in walk(first))
        # and only a command comes "first" ("first the light is red" is no order)
        return r.pick("precedence", used, allow=lambda p: (
            not ("after {a}" in p or "before {a}" in p) if command else "first" not in p),
            a=sub(first), b=sub(f.args[1].arg))
    patrol = _patrol(f, r)
    if patrol is not None:
        return r.pick("GF2_place", used, x=patrol[0], y=patrol[1])
    inner = _untimed(f, Eventually)
    if isinstance(inner, And) and len(inner.args) == 2:
        head, tail = inner.args
        if _untimed(tail, Always) is not None:
            return r.pick("F_then_G", used, a=sub(head), b=sub(tail.arg))
        deadline = tail.interval if isinstance(tail, Eventually) else None
        if deadline is not None and deadline.lo == 0 and deadline.hi is not None:
            # The second step has a deadline counted from the first.
            return r.pick("sequence_n", used, a=sub(head), b=sub(tail.arg), n=deadline.hi)
    if _is_xor(f):
        one, other = f.args[0].args
        return r.pick("xor", used, a=_choice(one, r, used, now), b=_choice(other, r, used, now))
    if isinstance(f, Always) and f.interval is None and isinstance(f.arg, Implies) \
            and _untimed(f.arg.rhs, Always) is not None:
        # "once the alarm sounds, keep the door closed from then on"
        lhs, kept = f.arg.lhs, f.arg.rhs.arg
        if isinstance(kept, Not) and isinstance(kept.arg, Atom) and (
                r.is_action(kept.arg.name) or not r.in_words):
            return r.pick("once_never", used, a=sub(lhs), b=sub(kept.arg))
        return r.pick("once_always", used, a=sub(lhs), b=sub(kept))
    if isinstance(f, Always) and f.interval is None and isinstance(f.arg, Implies):
        lhs, rhs = f.arg.lhs, f.arg.rhs
        if isinstance(rhs, Eventually) and (rhs.interval is None or (
                rhs.interval.lo == 0 and rhs.interval.hi and _untimed(rhs.arg, Always) is None)):
            command = isinstance(rhs.arg, Atom) and r.is_action(rhs.arg.name) \
                and not r.is_lasting(rhs.arg.name)
            if rhs.interval is None and command and r.rng is not None and r.rng.random() < 0.7:
                return r.pick("response_do", used, a=sub(lhs), b=sub(rhs.arg))
            if rhs.interval is None:
                return r.pick("response", used, a=sub(lhs), b=sub(rhs.arg))
            return r.pick("response_n", used, a=sub(lhs), b=sub(rhs.arg), n=rhs.interval.hi)
        if isinstance(lhs, Not) and isinstance(lhs.arg, Atom) and (isinstance(rhs, Atom) or (
                isinstance(rhs, (And, Or)) and all(_is_literal(g) for g in rhs.args))):
            # "keep the vacuum docked unless the house is empty"
            return r.pick("unless", used, a=sub(lhs.arg), b=sub(rhs))
        said = _negated(rhs, r) if isinstance(rhs, Not) else None
        if said is None and isinstance(rhs, Not) and isinstance(rhs.arg, Atom) \
                and r.is_action(rhs.arg.name) and r.rng is not None and r.rng.random() < 0.5:
            # "never touch the pan while the stove is on"
            return r.pick("invariant_not", used, a=sub(lhs), b=sub(rhs.arg))
        # "a only when b" needs a condition for b: "you charge only when hold the box"
        told = rhs.arg if isinstance(rhs, Not) else rhs
        command = isinstance(told, Atom) and r.is_action(told.name)
        return r.pick("invariant", used, allow=lambda p: _only(lhs)(p) and not (
            command and " only " in p), a=sub(lhs), b=said or sub(rhs))
    steps = _sequence(f)
    if steps is not None and len(steps) == 2:
        return r.pick("sequence", used, a=sub(steps[0]), b=sub(steps[1]))
    if steps is not None:
        # Three or more steps: the last two are one step of the three-step phrasing.
        last = r.pick("sequence", used, a=sub(steps[-2]), b=sub(steps[-1])) \
            if len(steps) > 3 else sub(steps[-1])
        middle = ", then ".join(sub(g) for g in steps[1:-2]) if len(steps) > 3 \
            else sub(steps[1])
        return r.pick("sequence3", used, a=sub(steps[0]), b=middle, c=last)
    if isinstance(f, Until) and f.interval is None and isinstance(f.lhs, Not):
        return r.pick("avoid_until", used, a=sub(f.lhs.arg), b=sub(f.rhs))
    return None


def held_for(f: Formula) -> tuple[Formula, int] | None:
    """``F(a & G[0,n](a))`` (a reached, and kept for ``n``) as ``(a, n)``, else ``None``."""
    inner = _untimed(f, Eventually)
    if not (isinstance(inner, And) and len(inner.args) == 2):
        return None
    head, tail = inner.args
    if isinstance(tail, Always) and tail.arg == head and tail.interval is not None \
            and tail.interval.lo == 0 and tail.interval.hi is not None:
        return head, tail.interval.hi
    return None


def _is_precedence(f: Formula) -> bool:
    """Whether ``f`` is ``(!b U a) & F(b)``: b at some point, not before a."""
    if not (isinstance(f, And) and len(f.args) == 2):
        return False
    until, later = f.args
    return (isinstance(until, Until) and until.interval is None and isinstance(until.lhs, Not)
            and isinstance(later, Eventually) and later.interval is None
            and later.arg == until.lhs.arg)


def _patrol(f: Formula, r: Realizer) -> tuple[str, str] | None:
    """The two places of ``G(F(a)) & G(F(b))`` over places, in half the sampled
    sentences where both have one, else ``None``."""
    if r.rng is None or not (isinstance(f, And) and len(f.args) == 2):
        return None
    found = [_untimed(_untimed(g, Always), Eventually) for g in f.args]
    if any(not isinstance(g, Atom) for g in found) or found[0] == found[1]:
        return None
    places = [r.say_place(g.name) for g in found]
    if None in places or r.rng.random() >= 0.5:
        return None
    return places[0], places[1]


def _choice(f: Formula, r: Realizer, used: list[str] | None, now: bool) -> str:
    """One side of "a or b, but not both": a command said bare, as a list of
    alternatives has it ("pick up the blue block or the green one"), not "please ..."."""
    arg = _untimed(f, Eventually)
    if now and isinstance(arg, Atom) and r.is_action(arg.name):
        return r.pick("F_do", used, allow=lambda p: p in _BARE_DO, a=r.say_atom(arg.name))
    return _say(f, r, used, embedded=True, now=now, plain=False)


def _is_xor(f: Formula) -> bool:
    """Whether ``f`` is ``(a | b) & !(a & b)``: exactly one of two."""
    if not (isinstance(f, And) and len(f.args) == 2):
        return False
    either, neither = f.args
    return (isinstance(either, Or) and len(either.args) == 2 and isinstance(neither, Not)
            and isinstance(neither.arg, And) and neither.arg.args == either.args)


def _visits(f: Formula) -> list[Formula] | None:
    """``F(a) & F(b) [& F(c)]`` over propositions (any bracketing) as ``[a, b(, c)]``,
    else ``None``."""
    if not isinstance(f, And):
        return None
    found = conjuncts(f)
    if 2 <= len(found) <= 3 and all(isinstance(g, Eventually) and g.interval is None
                                    and isinstance(g.arg, Atom) for g in found):
        return [g.arg for g in found]
    return None


def _sequence(f: Formula) -> list[Formula] | None:
    """``F(a & F(b & F(c)))`` as ``[a, b, c]``; ``None`` if ``f`` is no such chain."""
    if not (isinstance(f, Eventually) and f.interval is None and isinstance(f.arg, And)
            and len(f.arg.args) == 2):
        return None
    head, tail = f.arg.args
    if not (isinstance(tail, Eventually) and tail.interval is None):
        return None
    rest = _sequence(tail)
    if rest is None and _untimed(tail.arg, Always) is not None:
        # A last step for good is said whole ("then go to the dock and stay there"):
        # "first a, then always b" would be F(a & G(b)), b from a's moment on.
        return [head, tail]
    return [head] + (rest if rest is not None else [tail.arg])
