"""``ara stl ...`` and ``ara grammar``: the language core from the command line."""

from __future__ import annotations

import traceback
from enum import Enum

import typer

from ara.cli_support import EXIT_BAD_INPUT, EXIT_NO, emit, int_list, split_list, user_errors
from ara.errors import AraError, ConfigError
from ara.grammars.parser import parse
from ara.grammars.printer import to_text
from ara.grammars.stl_grammar import build_grammar
from ara.grammars.syntax import Syntax

SYNTAX_HELP = (
    "Syntax: propositions [A-Za-z_][A-Za-z0-9_]*, true, false; ! (not), & (and), | (or), "
    "-> (implies), <-> (iff); F (eventually), G (always), X (next), a U b (until); time "
    "windows in steps: F[2,5](a), G[0,30](!b), a U[0,4] b, F[3,inf](a). Loosest first: "
    "<->, ->, |, &, U, then the prefix operators. In full: docs/language.md."
)

stl_app = typer.Typer(
    help="Parse, print and compare STL formulas. " + SYNTAX_HELP,
    no_args_is_help=True,
)

JSON_OPT = typer.Option(False, "--json", help="Print one JSON object instead of text.")
TIMEOUT_OPT = typer.Option(
    60.0, "--timeout", min=0.1,
    help="Seconds Spot may take; past it, exit 3 (undecided). Wide windows nested under G "
         "take longest."
)


@stl_app.command("parse", short_help="Print a formula in canonical form.")
def parse_cmd(
    formula: str = typer.Argument(..., metavar="FORMULA",
                                  help="A formula, e.g. 'F(a) & G[0,30](!b)'."),
    as_json: bool = JSON_OPT,
) -> None:
    """Print FORMULA in canonical form; exit 2 naming the position if it is invalid.

    Syntax: propositions [A-Za-z_][A-Za-z0-9_]*, true, false; ! & | -> <->; F G X U, with
    time windows in steps: F[2,5](a), G[0,30](!b), a U[0,4] b (docs/language.md)."""
    with user_errors():
        tree = parse(formula)
    emit({"stl": to_text(tree), "valid": True}, as_json, lambda v: v["stl"])


@stl_app.command("explain", short_help="Read a formula back in plain English.")
def explain_cmd(
    formula: str = typer.Argument(..., metavar="FORMULA",
                                  help="A formula, e.g. 'G(door_open -> F[0,5](close))'."),
    as_json: bool = JSON_OPT,
) -> None:
    """Read FORMULA back in plain English, deterministically (same realizer as the data)."""
    from ara.grammars.english import explain

    with user_errors():
        tree = parse(formula)
    emit({"stl": to_text(tree), "english": explain(tree)}, as_json, lambda v: v["english"])


@stl_app.command("equiv", short_help="Whether A and B are equivalent (Spot).")
def equiv_cmd(
    a: str = typer.Argument(..., metavar="A", help="First formula."),
    b: str = typer.Argument(..., metavar="B", help="Second formula."),
    as_json: bool = JSON_OPT,
    timeout: float = TIMEOUT_OPT,
) -> None:
    """Whether A and B hold on exactly the same traces (decided by Spot).

    Exit 0: equivalent; 1: not; 2: bad input or Spot failed; 3: undecided in --timeout.
    """
    from ara.grammars.spot_bridge import equivalent

    _spot_verdict(equivalent, a, b, as_json, timeout, "equivalent",
                  ("equivalent", "not equivalent"))


@stl_app.command("implies", short_help="Whether A implies B (Spot).")
def implies_cmd(
    a: str = typer.Argument(..., metavar="A", help="Premise."),
    b: str = typer.Argument(..., metavar="B", help="Conclusion."),
    as_json: bool = JSON_OPT,
    timeout: float = TIMEOUT_OPT,
) -> None:
    """Whether A implies B: every trace satisfying A satisfies B (decided by Spot).

    Exit 0: it does; 1: it does not; 2: bad input or Spot failed; 3: undecided in --timeout.
    """
    from ara.grammars.spot_bridge import implies

    _spot_verdict(implies, a, b, as_json, timeout, "implies",
                  ("A implies B", "A does not imply B"))


def _spot_verdict(decide, a: str, b: str, as_json: bool, timeout: float, key: str,
                  words: tuple[str, str]) -> None:
    """Parse both formulas, ask Spot, print ``{key: verdict}`` or the verdict's words, and
    exit 1 for no, as diff and grep do, so a script can branch on the code alone."""
    with user_errors():
        try:
            result = decide(parse(a), parse(b), timeout_s=timeout)
        except (AraError, OSError, TimeoutError):
            raise
        except Exception:  # a crash exits 1 too, which would read as "no"
            traceback.print_exc()
            raise typer.Exit(EXIT_BAD_INPUT) from None
    emit({key: result}, as_json, lambda v: words[0] if result else words[1])
    if not result:
        raise typer.Exit(EXIT_NO)


class GrammarFormat(str, Enum):
    gbnf = "gbnf"
    lark = "lark"


def grammar_cmd(
    aps: str = typer.Option(..., "--aps", help="Comma-separated atomic propositions, e.g. a,b,c."),
    intervals: bool = typer.Option(
        False, "--intervals", help="Allow F[lo,hi], G[lo,hi], U[lo,hi]."
    ),
    max_bound: int = typer.Option(None, "--max-bound", min=0, show_default=False,
                                  help="Largest time bound in an interval (with --intervals) "
                                       "[default: 1000, what Spot can check]."),
    bounds: str = typer.Option(
        None, "--bounds", metavar="N,N,...",
        help="The only numbers an interval may use (with --intervals); ara translate "
             "allows 0 and the numbers the sentence writes."),
    allow_inf: bool = typer.Option(False, "--allow-inf",
                                   help="Allow [lo,inf] intervals (with --intervals)."),
    allow_next: bool = typer.Option(False, "--allow-next", help="Allow the next operator X."),
    relaxed: bool = typer.Option(
        False, "--relaxed",
        help="The paper's layout: precedence instead of parentheses, optional "
             "spaces, ! or ~ for not (default: the canonical layout ara stl parse prints).",
    ),
    max_depth: int = typer.Option(
        None, "--max-depth", min=1,
        help="Canonical layout: bound the nesting depth (finite language)."
    ),
    max_args: int = typer.Option(
        None, "--max-args", min=2, help="Canonical layout: bound the arguments of one & or |."
    ),
    fmt: GrammarFormat = typer.Option(GrammarFormat.gbnf, "--format", help="Output format."),
) -> None:
    """Print the grammar of STL over the given propositions (GBNF for llama.cpp, Lark for
    outlines/llguidance); its strings are exactly those the parser accepts in that layout.

    The formulas ara translate decodes a sentence into are this grammar's with
    --intervals --max-depth 5 --max-args 2 --bounds 0 and the sentence's numbers (a
    sentence with none: no --intervals).
    """
    with user_errors():
        if not intervals and (allow_inf or max_bound is not None or bounds is not None):
            raise ConfigError("--max-bound, --bounds and --allow-inf shape intervals: "
                              "add --intervals")
        bound = {} if max_bound is None else {"max_bound": max_bound}
        if bounds is not None:
            bound["bounds"] = int_list(bounds, "--bounds")
        syntax = Syntax(aps=split_list(aps), intervals=intervals, **bound,
                        allow_inf=allow_inf, allow_next=allow_next, relaxed=relaxed,
                        max_depth=max_depth, max_args=max_args)
        built = build_grammar(syntax)
    text = built.grammar.to_gbnf() if fmt is GrammarFormat.gbnf else built.grammar.to_lark()
    comment = "#" if fmt is GrammarFormat.gbnf else "//"
    typer.echo(f"{comment} ara grammar {built.version} sha256:{built.sha256[:16]}")
    typer.echo(text, nl=False)
