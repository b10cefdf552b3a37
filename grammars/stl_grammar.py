"""Build the grammar of a :class:`~ara.grammars.syntax.Syntax`, per request.

The request's atomic propositions become literals of the grammar, so a constrained
decoder can only name propositions the request has. Intervals are exact:
``[lo,hi]`` with ``lo <= hi <= max_bound`` and no leading zeros. A digit trie reads
``lo`` and then admits exactly the numbers from ``lo`` to ``max_bound``, so the
grammar holds no ambiguity that would multiply a decoder's parse stacks.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import lru_cache

from ara.errors import ConfigError
from ara.grammars.grammar_ir import Chars, Grammar, Item, Lit, Opt, Ref, Rule, Seq, Star
from ara.grammars.syntax import GRAMMAR_VERSION, Syntax

_DIGIT = Chars((("0", "9"),))

#: Largest ``max_bound`` a grammar is built for: the interval trie holds about two rules
#: per number up to the bound, and 10,000 already makes a ~1.5 MB grammar.
MAX_GRAMMAR_BOUND = 10_000


@dataclass(frozen=True)
class BuiltGrammar:
    """A grammar with what produced it.

    Attributes:
        syntax: The language options.
        grammar: The grammar IR; ``grammar.to_gbnf()`` and ``grammar.to_lark()`` emit it.
        version: :data:`~ara.grammars.syntax.GRAMMAR_VERSION` at build time.
    """

    syntax: Syntax
    grammar: Grammar
    version: str = GRAMMAR_VERSION

    @property
    def sha256(self) -> str:
        return self.grammar.sha256()

    def provenance(self) -> dict:
        """What every output that used this grammar records."""
        return {"grammar_version": self.version, "grammar_sha256": self.sha256,
                "syntax": self.syntax.to_dict()}


def build_grammar(syntax: Syntax) -> BuiltGrammar:
    """Build the grammar whose language is exactly ``syntax``'s.

    Raises:
        ConfigError: If ``syntax.aps`` is ``None``, or intervals are on with
            ``max_bound`` above :data:`MAX_GRAMMAR_BOUND`.
    """
    return _build_cached(syntax)


@lru_cache(maxsize=64)
def _build_cached(syntax: Syntax) -> BuiltGrammar:
    if syntax.aps is None:
        raise ConfigError(
            "a grammar is built per request from its atomic propositions: give aps, "
            "e.g. Syntax(aps=('prop_1', 'prop_2'))"
        )
    if syntax.intervals and syntax.max_bound > MAX_GRAMMAR_BOUND:
        raise ConfigError(
            f"max_bound={syntax.max_bound} would make a grammar of ~{2 * syntax.max_bound:,} "
            f"rules; grammars are built up to max_bound={MAX_GRAMMAR_BOUND:,}. Rescale the "
            "time unit (e.g. seconds instead of steps)"
        )
    # Longest names first keeps the emitted alternatives readable; order has no
    # effect on the language.
    names = sorted(syntax.aps, key=lambda n: (-len(n), n))
    atom = Rule("atom", tuple((Lit(n),) for n in ("true", "false", *names)))
    structure = _structure_rules(replace(syntax, aps=None))
    return BuiltGrammar(syntax, Grammar((atom, *structure), root="root"))


@lru_cache(maxsize=64)
def _structure_rules(layout: Syntax) -> tuple[Rule, ...]:
    """Every rule but ``atom``: they depend on the layout, never on the propositions,
    so requests with new propositions reuse them."""
    if not layout.intervals:
        rules = []
    elif layout.bounds is not None:
        rules = listed_interval_rules(layout.bounds, layout.allow_inf)
    else:
        rules = interval_rules(layout.max_bound, layout.allow_inf)
    rules += _relaxed_rules(layout) if layout.relaxed else _canonical_rules(layout)
    return tuple(rules)


def _canonical_rules(syntax: Syntax) -> list[Rule]:
    """The printer's layout; with ``max_depth``, one copy of the rules per depth level.

    Level ``d`` derives exactly the formulas of depth at most ``d``: an operator at
    level ``d`` takes its operands from level ``d - 1``, and level 0 is the atoms.
    """
    bounded = syntax.max_depth is not None
    levels = range(1, syntax.max_depth + 1) if bounded else [None]

    def name(base: str, level: int | None) -> str:
        return base if level is None else f"{base}_{level}"

    def below(base: str, level: int | None) -> Ref:
        if level is None:
            return Ref(base)
        return Ref("atom") if level == 1 else Ref(f"{base}_{level - 1}")

    rules: list[Rule] = []
    for lvl in levels:
        opnd, expr = below("opnd", lvl), below("expr", lvl)
        unary: list[Seq] = [(Ref("atom"),), (Lit("!"), opnd)]
        for op in ("F", "G"):
            unary.append((Lit(op + "("), expr, Lit(")")))
            if syntax.intervals:
                unary.append((Lit(op), Ref("interval"), Lit("("), expr, Lit(")")))
        if syntax.allow_next:
            unary.append((Lit("X("), expr, Lit(")")))
        tails: list[Seq] = [
            (Lit(" & "), opnd, *_more(Lit(" & "), opnd, syntax.max_args)),
            (Lit(" | "), opnd, *_more(Lit(" | "), opnd, syntax.max_args)),
            (Lit(" -> "), opnd),
            (Lit(" <-> "), opnd),
            (Lit(" U "), opnd),
        ]
        if syntax.intervals:
            tails.append((Lit(" U"), Ref("interval"), Lit(" "), opnd))
        rules += [
            Rule(name("expr", lvl), ((Ref(name("bin", lvl)),), (Ref(name("un", lvl)),))),
            Rule(name("opnd", lvl), ((Ref(name("un", lvl)),),
                                     (Lit("("), Ref(name("bin", lvl)), Lit(")")))),
            Rule(name("un", lvl), tuple(unary)),
            Rule(name("bin", lvl), ((opnd, Ref(name("tail", lvl))),)),
            Rule(name("tail", lvl), tuple(tails)),
        ]
    top = name("expr", syntax.max_depth if bounded else None)
    return [Rule("root", ((Ref(top),),)), *rules]


def _more(sep: Lit, item: Ref, max_args: int | None) -> Seq:
    """Further ``sep item`` repetitions after the first two arguments of & or |."""
    if max_args is None:
        return (Star((sep, item)),)
    nested: Seq = ()
    for _ in range(max_args - 2):
        nested = (Opt((sep, item, *nested)),)
    return nested


def _relaxed_rules(syntax: Syntax) -> list[Rule]:
    """Precedence layout; see :mod:`ara.grammars.syntax` for its whitespace rules."""
    ws = Ref("ws")
    until_op: list[Seq] = [(Lit(" U "), Ref("until"))]
    if syntax.intervals:
        until_op.append((Lit(" U"), Ref("interval"), Lit(" "), Ref("until")))
    # A word (proposition, keyword) directly after F, G or X needs one space;
    # '(' and '!' may follow with or without it.
    word_start: list[Seq] = [(Ref("atom"),)]
    prefixes = ["F", "G"] + (["X"] if syntax.allow_next else [])
    for op in prefixes:
        word_start += [(Lit(op), ws, Ref("unary_p")), (Lit(op + " "), Ref("unary_w"))]
        if syntax.intervals and op != "X":
            word_start.append((Lit(op), Ref("interval"), ws, Ref("unary")))
    return [
        Rule("root", ((Ref("iff"),),)),
        Rule("iff", ((Ref("imp"), Opt((ws, Lit("<->"), ws, Ref("imp")))),)),
        Rule("imp", ((Ref("or"), Opt((ws, Lit("->"), ws, Ref("imp")))),)),
        Rule("or", ((Ref("and"), Star((ws, Lit("|"), ws, Ref("and")))),)),
        Rule("and", ((Ref("until"), Star((ws, Lit("&"), ws, Ref("until")))),)),
        Rule("until", ((Ref("unary"),), *((Ref("unary"), *s) for s in until_op))),
        Rule("unary", ((Ref("unary_w"),), (Ref("unary_p"),))),
        Rule("unary_p", ((Ref("neg"), ws, Ref("unary")),
                         (Lit("("), ws, Ref("iff"), ws, Lit(")")))),
        Rule("unary_w", tuple(word_start)),
        Rule("neg", ((Lit("!"),), (Lit("~"),))),
        Rule("ws", ((Opt((Lit(" "),)),),)),
    ]


def interval_rules(max_bound: int, allow_inf: bool) -> list[Rule]:
    """``interval ::= "[" lo "," hi "]"`` with ``lo <= hi <= max_bound``, exactly.

    A trie over the digits of ``lo`` (rule ``lo_<digits>`` after reading them) hands
    over to ``ge_<lo>``, the numbers from ``lo`` to ``max_bound``.
    """
    rules = [Rule("interval", ((Lit("["), Ref("lo")),))]
    stack = [""]
    while stack:
        prefix = stack.pop()
        alts: list[Seq] = []
        if prefix:
            alts.append((Lit(","), Ref(f"ge_{prefix}"), Lit("]")))
            his: list[Seq] = [tuple(p) for p in number_patterns(int(prefix), max_bound)]
            if allow_inf:
                his.append((Lit("inf"),))
            rules.append(Rule(f"ge_{prefix}", tuple(his)))
        # "0" is a whole numeral: numerals have no leading zeros.
        if prefix != "0":
            for digit in "0123456789":
                nxt = prefix + digit
                if int(nxt) <= max_bound:
                    alts.append((Lit(digit), Ref(f"lo_{nxt}")))
                    stack.append(nxt)
        rules.append(Rule(f"lo_{prefix}" if prefix else "lo", tuple(alts)))
    return rules


def listed_interval_rules(bounds: tuple[int, ...], allow_inf: bool) -> list[Rule]:
    """``interval ::= "[" lo "," hi "]"`` with ``lo <= hi``, both from ``bounds``."""
    rules = [Rule("interval", ((Lit("["), Ref("lo")),)),
             Rule("lo", tuple((Lit(str(lo)), Lit(","), Ref(f"ge_{lo}"), Lit("]"))
                              for lo in bounds))]
    for lo in bounds:
        his: list[Seq] = [(Lit(str(hi)),) for hi in bounds if hi >= lo]
        if allow_inf:
            his.append((Lit("inf"),))
        rules.append(Rule(f"ge_{lo}", tuple(his)))
    return rules


def number_patterns(lo: int, hi: int) -> list[list[Item]]:
    """Digit patterns matching exactly the decimal numerals of ``lo..hi``.

    Each pattern is a list of items, one per digit. Numerals have no leading zeros.

    >>> len(number_patterns(7, 123))  # 7-9, 10-99, 100-119, 120-123
    4
    """
    patterns: list[list[Item]] = []
    for width in range(len(str(lo)), len(str(hi)) + 1):
        first = 0 if width == 1 else 10 ** (width - 1)
        last = 10**width - 1
        a, b = max(lo, first), min(hi, last)
        if a <= b:
            patterns += _same_width(str(a), str(b))
    return patterns


def _same_width(a: str, b: str) -> list[list[Item]]:
    """Patterns for the numerals from ``a`` to ``b``, both of the same width."""
    if not a:
        return [[]]
    if a[0] == b[0]:
        return [[Lit(a[0]), *rest] for rest in _same_width(a[1:], b[1:])]
    width = len(a) - 1
    low_full, high_full = a[1:] == "0" * width, b[1:] == "9" * width
    out: list[list[Item]] = []
    lo_digit, hi_digit = int(a[0]), int(b[0])
    if not low_full:
        out += [[Lit(a[0]), *rest] for rest in _same_width(a[1:], "9" * width)]
        lo_digit += 1
    if not high_full:
        hi_digit -= 1
    if lo_digit <= hi_digit:
        out.append([_digit_range(lo_digit, hi_digit)] + [_DIGIT] * width)
    if not high_full:
        out += [[Lit(b[0]), *rest] for rest in _same_width("0" * width, b[1:])]
    return out


def _digit_range(lo: int, hi: int) -> Item:
    return Lit(str(lo)) if lo == hi else Chars(((str(lo), str(hi)),))
