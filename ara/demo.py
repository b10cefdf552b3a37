"""``ara demo``: the toolkit end to end on the embedded defaults.

Prepare the versioned splits; for a few test pairs show the formula, the grammar built
from the pair's own propositions, and whether llama.cpp's grammar engine and Lark both
admit it; Spot's verdicts between pairs; then translate a few sentences of the
hand-written suite (never trained on) with the embedded Gemma 3 270M and its shipped
adapter under the grammar, judging each answer against the reference; last, the pallet
help round, with the forklifts translating the request by the same model.
"""

from __future__ import annotations

import random
from itertools import pairwise

import typer

from ara.eval.cli import SERVER, Server


def demo_cmd(
    n: int = typer.Option(4, "--n", min=1, max=20, help="How many test pairs to show."),
    seed: int = typer.Option(0, "--seed", help="Which pairs: the sampling seed."),
    model: str = typer.Option("finetuned", "--model",
                              help="Translator model (see ara translate): the shipped fine-tune "
                                   "by default; `default` is the embedded base model."),
    shots: int = typer.Option(None, "--shots", min=0, max=50,
                              help="Worked examples in the prompt [default: 0 for the "
                                   "fine-tune, which needs none; 5 otherwise]."),
    server: Server = SERVER,
) -> None:
    """Prepare the data, show grammar, parse and Spot checks, and translate a few pairs."""
    from ara.cli_support import user_errors
    from ara.eval.translate.models import shared_backend

    with user_errors():
        shared_backend(model, server=server)  # a bad --model is refused before the long part
        _demo(n, seed, model, shots, server)


def _demo(n: int, seed: int, model: str, shots: int | None, server: str) -> None:
    import lark

    from ara.data import SPLITS, prepare
    from ara.eval.translate.llama_check import LlamaGrammarChecker
    from ara.grammars import Syntax, build_grammar, parse
    from ara.grammars.spot_bridge import equivalent, implies

    typer.echo("== data: versioned splits")
    for split in SPLITS:
        p = prepare(split, 0)
        counts = ", ".join(f"{k} {sum(v.values())}" for k, v in p.manifest["counts"].items())
        typer.echo(f"  {p.folder.name}: {counts} records, "
                   f"{p.manifest['rejected']['count']} raw rows rejected")
    test = prepare("paper", 0).records("test")
    picks = random.Random(seed).sample(test, n)

    typer.echo("\n== grammar + parse: each formula under the grammar of its own propositions")
    for r in picks:
        syntax = Syntax(aps=r.aps)
        built = build_grammar(syntax)
        gbnf = LlamaGrammarChecker(built.grammar.to_gbnf()).accepts(r.stl)
        larked = _lark_accepts(lark, built.grammar.to_lark(), r.stl)
        typer.echo(f"  [{r.form}] {r.nl}\n      STL  {r.stl}\n      grammar {built.version} "
                   f"sha256:{built.sha256[:12]}  parser={syntax.accepts(r.stl)} "
                   f"llama.cpp={gbnf} lark={larked}")

    typer.echo("\n== Spot: equivalence and implication between the lifted formulas")
    lifted = [r for r in prepare("paper", 0).records("test", "lifted")]
    sample = random.Random(seed + 1).sample(lifted, 6)
    for a, b in pairwise(sample):
        fa, fb = parse(a.stl), parse(b.stl)
        typer.echo(f"  {a.stl:<32} vs {b.stl:<32} equivalent={equivalent(fa, fb)!s:<5} "
                   f"A=>B={implies(fa, fb)!s:<5} B=>A={implies(fb, fa)}")
    noisy = ("F(prop_1 | F(prop_2))", "F(prop_1) | F(prop_2)")
    typer.echo(f"  {noisy[0]:<32} vs {noisy[1]:<32} equivalent="
               f"{equivalent(parse(noisy[0]), parse(noisy[1]))}  (NL2TL's two spellings)")
    if shots is None:
        from ara.eval.translate.models import default_shots

        shots = default_shots(model)
    translator = _translate_some(model, n, seed, shots, server)
    _help_round(translator)


def _help_round(translator) -> None:
    """The paper's pallet scenario: each forklift translates the request and bids."""
    from ara.coordination.demos import run_demo

    typer.echo("\n== help request: forklifts translate the request with the same model, "
               "plan with the event MILP, and bid")
    run_demo("pallet", "runs/demos", translator,
             lambda line: typer.echo(f"  {line}"))


def _translate_some(model: str, n: int, seed: int, k: int, server: str):
    from ara.data import prepare
    from ara.eval.translate.models import shared_backend
    from ara.eval.translate.prompt import sample_shots
    from ara.eval.translate.translator import Translator
    from ara.grammars.spot_bridge import judge

    rng = random.Random(seed)
    pool = prepare("compositional", 0).records("train", "grounded")
    shots = sample_shots(pool, k, rng) if k else []
    translator = Translator(shared_backend(model, server=server))
    typer.echo(f"\n== translate: hand-written sentences no model trained on; "
               f"{translator.backend.model_id}, {k} shots, grammar-constrained")
    for r in rng.sample(prepare("handwritten", 0).records("test", "grounded"), n):
        result = translator.translate(r.nl, r.aps, shots)
        verdict = judge(r.stl, result.stl, timeout_s=10)
        typer.echo(f"  {r.nl}\n      model {result.stl}   ({result.ms:.0f} ms)\n"
                   f"      truth {r.stl}\n      equivalent={verdict['equivalent']} "
                   f"model=>truth={verdict['implies']}")
    return translator


def _lark_accepts(lark, grammar_text: str, text: str) -> bool:
    try:
        lark.Lark(grammar_text, start="start", parser="earley", lexer="dynamic").parse(text)
    except lark.exceptions.LarkError:
        return False
    return True
