"""The words by which a sentence asks for a construct, beside the realizer's phrasings
for it (:mod:`ara.grammars.english`), which they must recognise.

Each list holds the words that ask for its construct whatever the rest of the sentence
says; "whenever", "within" and "during" can mean either of ``F`` and ``G`` and are in
none. The lists read a sentence in lower case.
"""

from __future__ import annotations

import re

from ara.grammars.nesting import AFTER_WINDOW, AGAIN_AND_AGAIN, FOR_GOOD, HAPPENS, HOLDS

#: Numbers a sentence may write in words.
NUMBER_WORDS = {w: i for i, w in enumerate(
    "zero one two three four five six seven eight nine ten eleven twelve thirteen fourteen "
    "fifteen sixteen seventeen eighteen nineteen twenty".split())}
NUMBER_WORDS |= {w: 10 * (i + 3) for i, w in enumerate(
    "thirty forty fifty sixty seventy eighty ninety".split())} | {"hundred": 100}
#: Words next to which a number word is a time ("ten steps", "step ten").
TIME_WORDS = frozenset("step steps time second seconds minute minutes hour hours unit units "
                       "tick ticks instant instants moment moments".split())

#: Words that allow ``G(F(a))``: a again and again.
AGAIN_AND_AGAIN_WORDS = re.compile(
    r"\b(again|repeatedly|over and over|time and again|time after time|infinitely|often"
    r"|periodic\w*"
    r"|regularly|every so often|now and then|from time to time|always eventually"
    r"|keep (?:on )?(?:visiting|revisiting|coming|returning|going|checking|patrolling"
    r"|circling|cycling)|back and forth|patrol\w*|alternat\w*|recurr\w*|endless\w*"
    r"|cycl\w*|loop\w*|round|never stops?|continual\w*|routine\w*)\b")
#: Words that say something lasts: they ask for it to hold (:data:`HOLDS_WORDS`) and
#: allow it from some point on, for good (:data:`FOR_GOOD_WORDS`).
_LASTING = r"always|at all times|forever|for good|permanently|keep|remain|remains|remaining"
#: Words that allow ``F(G(a))``: a from some point on, for good.
FOR_GOOD_WORDS = re.compile(
    rf"\b({_LASTING}|stay|stays|staying"
    r"|from (?:then|now|there) on|from (?:that|this|the|some) (?:moment|point|time|step) on"
    r"|eventually always|thereafter|ever after|onwards?|henceforth|indefinitely|in the end"
    r"|ultimately|ends? up|settles?|continu\w*"
    r"|(?<!not )(?<!n't )leave (?:it|them) (?:there|in place)"
    r"|never(?: (?!and\b|then\b|or\b)[\w']+){1,4} again(?! and again)"
    r"|uninterrupted\w*|consecutive\w*|consistently|(?:until|till) the (?:very )?end)\b")
#: Words that order steps: "go to the dock, then charge". A ", then" after a condition
#: ("if a, then b") orders nothing, nor does "sooner or later".
SEQUENCE_WORDS = re.compile(
    r"\b(and then|after that|afterwards?|followed by|one after the other|in (?:that|this) order"
    r"|subsequently|(?<!no )(?<!sooner or )later)\b")
THEN = re.compile(r"[,;] then\b")
#: Words that may open a condition, for :func:`says_in_order` (a ", then" after one
#: closes the condition, it orders nothing); :data:`CONDITION_CLAUSE` is the narrower
#: list whose clauses the condition check reads, where a wrong reading costs more.
CONDITION_WORDS = re.compile(r"\b(if|when|whenever|in case|in the case|in the event|provided"
                             r"|as soon as|once|while|on condition|every ?time|each time)\b")
#: Words that open a condition: what the clause after them names is read before the
#: arrow ("whenever the bin is full, empty it": ``G(bin_full -> F(empty_bin))``).
#: "Even if" and "as if" open none, nor "at once", "at least once" or "once every" (a
#: rate); "when possible" is NL2TL's "at some point"; "while" after a comma is often a
#: contrast ("a happens often, while b never does").
CONDITION_CLAUSE = re.compile(
    r"\b(?<!even )(?<!as )(whenever|if|when|each time|every ?time"
    r"|(?<!at )(?<!least )(?<!than )(?<!exactly )once|as soon as"
    r"|(?<![,;] )while|as long as|in case|in the event(?: that| of)?|provided(?: that)?)\b"
    r"(?! possible| (?:every|more|in a while|again)\b)")
#: Sentences whose condition words do not say which side is the condition: "a only if
#: b", "a only when b" and "unless" turn it round, "a means that b" puts it first, "if
#: and only if" puts it on both sides.
NO_CONDITION_CLAUSE = re.compile(r"\b(only|unless|except|means|infers?|implies|iff)\b")
#: Words that negate what a clause says, or all of it before something ("when no
#: cashier is at the register", "if you always avoid the gate", "if you wait until b
#: before a": ``!a U b``).
NEGATION_WORDS = re.compile(r"\b(no|not|never|none|nobody|nothing|neither|nor|without|false"
                            r"|avoid\w*|away|out of|until|till|before)\b|n't\b")
#: What ends a condition clause ("if the door opens, stop").
_CLAUSE_END = re.compile(r"[,;.:!?]| then\b")


def condition_clauses(text: str) -> list[tuple[int, int]]:
    """The spans of ``text`` (lower case) that name a condition: each from a word of
    :data:`CONDITION_CLAUSE` to the next comma or "then", none where the sentence's
    words leave the direction open (:data:`NO_CONDITION_CLAUSE`)."""
    if NO_CONDITION_CLAUSE.search(text):
        return []
    spans = []
    for m in CONDITION_CLAUSE.finditer(text):
        end = _CLAUSE_END.search(text, m.end())
        spans.append((m.end(), end.start() if end else len(text)))
    return spans


#: Words that ask for no order between steps.
ANY_ORDER_WORDS = re.compile(
    r"\b(in (?:any|either|whatever|whichever) order|(?:the )?order does not matter"
    r"|regardless of (?:the )?order|no matter (?:the|what|which) order)\b")
#: Words that ask for something to hold over a stretch of time (:data:`HOLDS`). "Stay
#: still" and "stay at the kitchen" name propositions in the realizer's words (``wait``,
#: ``at_kitchen``), and "a or b, never both" is an exclusive or, so those ask nothing.
HOLDS_WORDS = re.compile(
    rf"\b({_LASTING}|all the time|never(?! both)|at no time"
    r"|constantly|continuously|throughout|every ?time|each time|keeps|keeping"
    r"|(?:stay|stays|staying)(?! still| at)|avoid\w*|until|till"
    r"|for (?:the )?(?:next |first |whole |entire )?(?:\d+|[a-z]+ (?:steps|seconds|minutes)))\b")
#: Words that ask for something to happen at some point (:data:`HAPPENS`).
HAPPENS_WORDS = re.compile(
    r"\b(eventually|at some (?:point|time|moment|step)|sooner or later|at least once"
    r"|sometime|someday|ultimately|finally|in the end|at one point"
    r"|(?:by|no later than|before) (?:time step|step|time|second|minute|hour) \d+)\b")
#: Words that ask for something again and again (:data:`AGAIN_AND_AGAIN`), a strict
#: part of :data:`AGAIN_AND_AGAIN_WORDS`: each of these says it, not only allows it.
RECURRING_WORDS = re.compile(
    r"\b(again and again|repeatedly|over and over|time and again|time after time"
    r"|infinitely often"
    r"|every so often|now and then|from time to time|periodically|regularly"
    r"|keep (?:on )?(?:visiting|revisiting|coming back|returning|going back|checking"
    r"|patrolling|circling|cycling)|patrol\w*|back and forth"
    r"|(?:at least )?once (?:in )?every|in every [\w-]+ (?:window|period|interval))\b")

#: The words that ask for each temporal claim, in the order claims are reported.
CLAIM_WORDS = {HOLDS: HOLDS_WORDS, HAPPENS: HAPPENS_WORDS, AGAIN_AND_AGAIN: RECURRING_WORDS}
#: The words that allow each nested pair of ``F`` and ``G``: ``G[0,5](F(a))`` only where
#: the sentence says a happens at some point ("for every moment of the next 5, at some
#: point later a", as NL2TL's timed rows put it). Like the others, a word anywhere in
#: the sentence allows it, even one about another proposition: the check stays one-sided.
NESTING_WORDS = {AGAIN_AND_AGAIN: AGAIN_AND_AGAIN_WORDS, FOR_GOOD: FOR_GOOD_WORDS,
                 AFTER_WINDOW: HAPPENS_WORDS}


def says_in_order(text: str) -> bool:
    """Whether ``text`` puts one step after another: a word of order, or a ", then" not
    ending a condition, unless it also says "in any order"."""
    if ANY_ORDER_WORDS.search(text):
        return False
    if SEQUENCE_WORDS.search(text):
        return True
    then = THEN.search(text)
    return then is not None and not CONDITION_WORDS.search(text[:then.start()])
