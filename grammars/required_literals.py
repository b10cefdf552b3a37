"""Grammars whose strings must write given literals: "an answer that uses ``prop_3``".

A translation that leaves out a proposition the user listed is wrong whatever else it
says (:mod:`ara.eval.translate.checks`). :func:`require_literals` turns a request's grammar
into one that admits exactly its strings whose derivation writes each given literal
(a proposition, a bound of the listed-bounds interval rules) at least once, so a
decoder under it cannot leave them out.

The construction is the product of the grammar with a two-state automaton ("seen the
literal yet?"), one literal at a time. Each rule ``A`` that can reach the literal gets
two copies: ``A_not`` (derivations without it) and ``A_has`` (with it). A sequence
has it when some item is the *first* to have it: the items before that one are
``_not`` copies and the items after keep the original rule. Splitting at the first
occurrence keeps an unambiguous grammar unambiguous, so a decoder's parse stacks do
not multiply. Rules that cannot reach the literal are shared unchanged, which keeps
the interval tries out of the copy when the literal is a proposition.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

from ara.grammars.grammar_ir import Grammar, Item, Lit, Opt, Ref, Rule, Seq, Star


def require_literals(grammar: Grammar, texts: Iterable[str]) -> Grammar:
    """The strings of ``grammar`` whose derivation writes every literal of ``texts``.

    A literal counts where it is a whole :class:`Lit` item of the grammar (the
    proposition ``a`` does not occur inside ``a_b``, nor the bound 10 inside 100).

    Raises:
        ValueError: If no string of ``grammar`` writes them all (e.g. a literal the
            grammar never writes).
    """
    for text in dict.fromkeys(texts):
        grammar = _require_one(grammar, text)
    return grammar


def _require_one(grammar: Grammar, text: str) -> Grammar:
    marker = Lit(text)
    reaches = _rules_reaching(grammar, marker)
    if grammar.root not in reaches:
        raise ValueError(f"the grammar never writes {text!r}")
    taken = {r.name for r in grammar.rules}

    def fresh(base: str) -> str:
        name = base
        while name in taken:
            name += "_"
        taken.add(name)
        return name

    not_name = {n: fresh(f"{n}_not") for n in sorted(reaches)}
    has_name = {n: fresh(f"{n}_has") for n in sorted(reaches)}
    helpers: list[Rule] = []

    def without(seq: Seq) -> Seq | None:
        """``seq`` restricted to derivations without the literal; None if it has none."""
        return _restricted(seq, lambda item: None if item == marker else (
            Ref(not_name[item.name]) if isinstance(item, Ref) and item.name in reaches
            else item))

    def with_it(seq: Seq, owner: str) -> list[Seq]:
        """``seq``'s derivations with the literal, as alternatives split at its first
        occurrence."""
        alts: list[Seq] = []
        for k, item in enumerate(seq):
            before = without(seq[:k])
            if before is None:
                break  # an earlier item always writes the literal
            for first in item_with_it(item, owner):
                alts.append((*before, *first, *seq[k + 1:]))
        return alts

    def item_with_it(item: Item, owner: str) -> list[Seq]:
        if item == marker:
            return [(item,)]
        if isinstance(item, Ref):
            return [(Ref(has_name[item.name]),)] if item.name in reaches else []
        if isinstance(item, (Opt, Star)):
            inner = with_it(item.items, owner)
            if not inner:
                return []
            middle = inner[0] if len(inner) == 1 else (Ref(helper(owner, inner)),)
            if isinstance(item, Opt):
                return [middle]
            skipped = without(item.items)
            head: Seq = (Star(skipped),) if skipped else ()
            return [(*head, *middle, item)]
        return []

    def helper(owner: str, alts: list[Seq]) -> str:
        name = fresh(f"{owner}_part")
        helpers.append(Rule(name, tuple(alts)))
        return name

    rules: list[Rule] = list(grammar.rules)
    for rule in grammar.rules:
        if rule.name not in reaches:
            continue
        plain = tuple(s for s in (without(a) for a in rule.alts) if s is not None)
        marked = tuple(s for a in rule.alts for s in with_it(a, has_name[rule.name]))
        rules.append(Rule(not_name[rule.name], plain))
        rules.append(Rule(has_name[rule.name], marked))
    return _pruned([*rules, *helpers], has_name[grammar.root])


def _rules_reaching(grammar: Grammar, marker: Lit) -> set[str]:
    """Names of the rules with a derivation that writes ``marker``."""

    def writes(items: Seq, found: set[str]) -> bool:
        return any(item == marker
                   or (isinstance(item, Ref) and item.name in found)
                   or (isinstance(item, (Opt, Star)) and writes(item.items, found))
                   for item in items)

    found: set[str] = set()
    changed = True
    while changed:
        changed = False
        for rule in grammar.rules:
            if rule.name not in found and any(writes(a, found) for a in rule.alts):
                found.add(rule.name)
                changed = True
    return found


def _pruned(rules: list[Rule], root: str) -> Grammar:
    """The grammar of ``rules`` without what derives nothing (a ``_not`` copy of a rule
    that always writes the literal, the alternatives that use one) and without the
    rules the root never uses."""
    by_name = {r.name: r for r in rules}
    live: set[str] = set()

    def finite(items: Seq) -> Seq | None:
        return _restricted(items, lambda item: None if isinstance(item, Ref)
                           and item.name not in live else item)

    changed = True
    while changed:
        changed = False
        for rule in rules:
            if rule.name not in live and any(finite(a) is not None for a in rule.alts):
                live.add(rule.name)
                changed = True
    if root not in live:
        raise ValueError("no string of the grammar writes every required literal")
    used, stack = [], [root]
    while stack:
        name = stack.pop()
        if name in used:
            continue
        used.append(name)
        kept = tuple(s for s in map(finite, by_name[name].alts) if s is not None)
        by_name[name] = Rule(name, kept)
        stack.extend(_refs(kept))
    return Grammar(tuple(by_name[r.name] for r in rules if r.name in used), root=root)


def _restricted(seq: Seq, swap: Callable[[Item], Item | None]) -> Seq | None:
    """``seq`` with each plain item replaced by ``swap(item)``; None if ``swap`` forbids
    one. An optional or repeated part that holds a forbidden item is skipped instead,
    since skipping it is still a derivation."""
    out: list[Item] = []
    for item in seq:
        if isinstance(item, (Opt, Star)):
            inner = _restricted(item.items, swap)
            if inner is not None:
                out.append(type(item)(inner))
            continue
        new = swap(item)
        if new is None:
            return None
        out.append(new)
    return tuple(out)


def _refs(alts: Iterable[Seq]) -> list[str]:
    out: list[str] = []
    for seq in alts:
        for item in seq:
            if isinstance(item, Ref):
                out.append(item.name)
            elif isinstance(item, (Opt, Star)):
                out.extend(_refs([item.items]))
    return out
