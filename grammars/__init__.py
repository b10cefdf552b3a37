"""The STL language core: tree, parser, printer, grammars and the Spot bridge.

Everything else in the toolkit reads and writes formulas through this package.
"""

from ara.grammars.ast import (
    KEYWORDS,
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
    atoms,
    depth,
    max_bound,
    walk,
)
from ara.grammars.parser import parse
from ara.grammars.printer import to_text
from ara.grammars.required_literals import require_literals
from ara.grammars.stl_grammar import BuiltGrammar, build_grammar
from ara.grammars.syntax import GRAMMAR_VERSION, Syntax

__all__ = [
    "GRAMMAR_VERSION",
    "KEYWORDS",
    "Always",
    "And",
    "Atom",
    "BuiltGrammar",
    "Const",
    "Eventually",
    "Formula",
    "Iff",
    "Implies",
    "Interval",
    "Next",
    "Not",
    "Or",
    "Syntax",
    "Until",
    "atoms",
    "build_grammar",
    "depth",
    "max_bound",
    "parse",
    "require_literals",
    "to_text",
    "walk",
]
