"""``ara translate`` and ``ara eval ...``: translate one sentence, run and score ablations."""

from __future__ import annotations

import random
import signal
from pathlib import Path

import typer

from ara.cli_support import emit, split_list, user_errors
from ara.errors import ConfigError
from ara.eval.confidence import DOUBT
from ara.eval.consistency import DEFAULT_REPAIR as REPAIR
from ara.eval.consistency import REPAIR_BY, translate_consistent, translate_repaired

eval_app = typer.Typer(help="The F/P/C ablation of the paper's Experiment 1.",
                       no_args_is_help=True)

MODEL_HELP = ("default (embedded Gemma 3 270M), finetuned (its shipped LoRA), lora:ADAPTER.gguf "
              "(another LoRA on the same base), a .gguf path, hf:FOLDER, or an "
              "OpenAI-compatible http(s):// endpoint")
SERVER_HELP = ("With an http(s):// --model: the server that runs it, which says where it reads "
               "the grammar for constrained decoding: llama (llama.cpp, llama-cpp-python), "
               "vllm, sglang, or openai (no grammar; constrained variants are refused).")


def translate_cmd(
    nl: str = typer.Argument(..., help="The instruction, e.g. 'always avoid the door'."),
    aps: str = typer.Option(..., "--aps", help="Comma-separated atomic propositions, each "
                            "named in the sentence (go_to_kitchen: 'go to the kitchen')."),
    model: str = typer.Option("finetuned", "--model", help=MODEL_HELP),
    no_constraint: bool = typer.Option(False, "--no-constraint",
                                       help="Decode freely instead of under the grammar."),
    grammar_in_prompt: bool = typer.Option(False, "--grammar-in-prompt",
                                           help="Show the grammar in the prompt."),
    shots: int | None = typer.Option(
        None, "--shots", min=0, max=50,
        help="Worked examples from the compositional train side; default 0 for the "
             "fine-tuned adapters, 5 for other models."),
    seed: int = typer.Option(0, "--seed", help="Which worked examples."),
    intervals: bool = typer.Option(
        True, "--intervals/--no-intervals",
        help="Allow time bounds (F[a,b], G[a,b], U[a,b]); on by default, and an untimed "
             "sentence still comes out untimed."),
    max_bound: int = typer.Option(1000, "--max-bound", min=1,
                                  help="Largest time bound the grammar admits."),
    any_bound: bool = typer.Option(
        False, "--any-bound",
        help="Let intervals use any number up to --max-bound; by default they use only 0 "
             "and the numbers the sentence writes (digits, or words up to 'hundred')."),
    samples: int = typer.Option(
        1, "--samples", min=1, max=32,
        help="Self-consistency: K answers under the grammar (greedy + K-1 sampled), "
             "grouped by Spot equivalence; the largest group wins. 1: greedy."),
    temperature: float = typer.Option(0.7, "--temperature", min=0.01,
                                      help="Sampling temperature for --samples and --repair."),
    repair: int | None = typer.Option(
        None, "--repair", min=0, max=32,
        help=f"When the greedy answer leaves out a proposition in --aps or a number the "
             f"sentence states as time, look for an answer that leaves out less (a "
             f"complete greedy answer costs nothing more), drawing K answers under the "
             f"grammar (see --repair-by). Default {REPAIR}, or 0 with --samples; 0: off."),
    repair_by: str = typer.Option(
        REPAIR_BY[0], "--repair-by",
        help="samples+edits: the K answers drawn and the formulas one edit from the "
             "greedy answer that write what it left out; the one the model scores "
             "highest of those that leave out least wins. edits: the edits alone. "
             "samples: the majority of the K drawn that leave out least (also what the "
             "others do with an HTTP --model, which cannot score)."),
    doubt: float = typer.Option(
        DOUBT, "--doubt", min=0.0, max=1.0,
        help="With repair by samples+edits: also draw the K answers when the greedy "
             "answer leaves nothing out but the model gives it a probability below this, "
             "and keep the best-scored complete one. 0: repair answers with a gap only."),
    server: str = typer.Option("openai", "--server", help=SERVER_HELP),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON object."),
) -> None:
    """Translate one instruction into STL over the given propositions.

    Prints the formula. On stderr: a warning when it leaves out a listed
    proposition or a stated bound, and a note with the formula read back in
    English when the model gives its answer a probability below 0.5 (about
    half of such held-out answers were wrong). --json has it as "confidence".
    """
    from ara.data import load_or_prepare
    from ara.data.normalize import form_of
    from ara.eval.confidence import doubt_warning, result_probability, winner_probability
    from ara.eval.coverage import gaps
    from ara.eval.models import default_shots, make_backend
    from ara.eval.prompt import sample_shots
    from ara.eval.translator import Translator, TranslatorConfig, check_request
    from ara.grammars import parse

    with user_errors():
        names = split_list(aps)
        config = TranslatorConfig(intervals=intervals, max_bound=max_bound,
                                  bounds_from_request=not any_bound)
        check_request(nl, names, config)
        if samples > 1 and no_constraint:
            raise ConfigError("--samples decodes under the grammar (every sample valid); "
                              "drop --no-constraint")
        if samples > 1 and repair:
            raise ConfigError("--samples and --repair are two ways to spend extra answers; "
                              "pass one")
        if repair and no_constraint:
            raise ConfigError("--repair decodes under the grammar; drop --no-constraint")
        if repair_by not in REPAIR_BY:
            raise ConfigError(f"--repair-by {repair_by!r}? choose one of {', '.join(REPAIR_BY)}")
        if repair is None:
            repair = 0 if samples > 1 or no_constraint else REPAIR
        k = shots if shots is not None else default_shots(model)
        pool = load_or_prepare("compositional").records("train", form_of(names))
        examples = sample_shots(pool, k, random.Random(seed)) if k else []
        translator = Translator(make_backend(model, server=server), config)
        vote = None
        if samples > 1:
            vote = translate_consistent(translator, nl, names, examples, samples, temperature,
                                        seed, grammar_in_prompt=grammar_in_prompt)
            result = vote.result
        elif repair:
            vote = translate_repaired(translator, nl, names, examples, repair, temperature,
                                      seed, grammar_in_prompt=grammar_in_prompt, by=repair_by,
                                      doubt=doubt)
            result = vote.result
        else:
            result = translator.translate(nl, names, examples, grammar_in_prompt,
                                          constrained=not no_constraint)
    data = {"stl": result.stl, "valid": result.valid, "raw": result.raw,
            "ms": round(vote.ms if vote else result.ms, 1), "error": result.error,
            "model": translator.backend.model_id, "constrained": result.constrained,
            "shots": k, "grammar": result.grammar}
    if vote is not None:
        data["samples"] = {"answers": list(vote.answers), "groups": [list(g) for g in vote.groups],
                           "agreement": round(vote.agreement, 3)}
        if vote.scores:
            data["samples"]["scores"] = [None if x is None else round(x, 3)
                                         for x in vote.scores]
    with user_errors():
        probability = (winner_probability(translator, vote, examples, grammar_in_prompt)
                       if vote else result_probability(translator, result, examples,
                                                       grammar_in_prompt))
    data["confidence"] = None if probability is None else round(probability, 3)
    if result.stl is not None:
        gap = gaps(nl, names, parse(result.stl))
        data["left_out"] = {"aps": list(gap.aps), "numbers": list(gap.numbers)}
        if gap and not as_json:
            typer.echo(gap.warning(), err=True)
        if probability is not None and probability < DOUBT and not as_json:
            typer.echo(doubt_warning(result.stl, probability), err=True)
    emit(data, as_json, lambda d: d["stl"] if d["valid"] else f"invalid: {d['error']}\n{d['raw']}")


@eval_app.command("ablation")
def ablation_cmd(
    out: Path = typer.Option(..., "--out", help="Run folder: samples.jsonl, results.json, ..."),
    split: str = typer.Option("paper", "--split",
                              help="paper, disjoint, timed, compositional (held-out shapes "
                                   "and phrasings), handwritten (the hand-written suite) "
                                   "or handwritten2 (the second, never read for data)."),
    form: str = typer.Option("lifted", "--form", help="lifted or grounded."),
    variants: str = typer.Option("F,F+P,F+P+C", "--variants",
                                 help="Comma list of variants: letters F, P, C joined by "
                                      "+, or none (zero-shot, unconstrained)."),
    shots: str = typer.Option("5,20", "--shots", help="Comma list of few-shot counts."),
    reruns: int = typer.Option(3, "--reruns", help="Reruns, each with new examples."),
    limit: int = typer.Option(1000, "--limit", help="Test pairs to sample."),
    seed: int = typer.Option(0, "--seed", help="Seeds the test sample and the examples."),
    model: str = typer.Option("default", "--model", help=MODEL_HELP),
    mask: str = typer.Option("llguidance", "--mask",
                             help="Constraint engine: llguidance (fast) or llama (built-in)."),
    spot_timeout: float = typer.Option(10.0, "--spot-timeout",
                                       help="Seconds per Spot check before 'undecided'."),
    resume: bool = typer.Option(False, "--resume", help="Continue the run in --out."),
    no_progress: bool = typer.Option(False, "--no-progress", help="Hide the progress bar."),
    server: str = typer.Option("openai", "--server", help=SERVER_HELP),
    concurrency: int = typer.Option(
        1, "--concurrency",
        help="Requests in flight at once, for an http(s):// --model (the server batches "
             "them); samples are still written in order, and --resume works as usual."),
    repair: int = typer.Option(
        0, "--repair", min=0, max=32,
        help="Constrained variants: when the greedy answer leaves out a listed proposition "
             "or a number the sentence states, look for an answer that leaves out less, "
             "drawing K more (see --repair-by). 0 (the paper's variants): greedy."),
    repair_by: str = typer.Option(
        REPAIR_BY[0], "--repair-by",
        help="samples+edits (the model's best-scored of the K drawn and the greedy "
             "answer's one-edit mends), edits (the mends alone) or samples (the majority "
             "of the K drawn)."),
    doubt: float = typer.Option(
        DOUBT, "--doubt", min=0.0, max=1.0,
        help="With --repair by samples+edits: also draw for a complete greedy answer the "
             "model gives a probability below this (0: answers with a gap only)."),
) -> None:
    """Run the F/P/C ablation and write samples, results, tables and a plot to --out."""
    from ara.eval.ablation import run_ablation
    from ara.eval.harness import AblationConfig
    from ara.eval.models import make_backend
    from ara.eval.report import tables_markdown

    # SIGTERM ends the run like Ctrl-C: finished samples stay, the report is written.
    signal.signal(signal.SIGTERM, signal.default_int_handler)
    with user_errors():
        config = AblationConfig(
            split=split, form=form, variants=split_list(variants),
            shots=tuple(int(k) for k in split_list(shots)), reruns=reruns, limit=limit,
            seed=seed, model=model, spot_timeout_s=spot_timeout, repair=repair,
            repair_by=repair_by, repair_doubt=doubt,
        )
        backend = make_backend(model, mask=mask, server=server)
        try:
            results = run_ablation(config, backend, out, resume, progress=not no_progress,
                                   concurrency=concurrency)
        except KeyboardInterrupt:
            typer.echo(f"interrupted: finished samples are in {out}; continue with --resume",
                       err=True)
            raise typer.Exit(130) from None
    typer.echo(tables_markdown(results))
    typer.echo(f"wrote {out}/samples.jsonl, results.json, tables.md, plot.png")


@eval_app.command("score")
def score_cmd(
    folder: Path = typer.Argument(..., help="A run folder from `ara eval ablation`."),
    as_json: bool = typer.Option(False, "--json", help="Print results.json instead of tables."),
) -> None:
    """Re-score a run from its samples.jsonl (no model needed) and rewrite its report."""
    from ara.eval.report import tables_markdown, write_report

    with user_errors():
        results = write_report(folder)
    emit(results, as_json, tables_markdown)


@eval_app.command("ceiling")
def ceiling_cmd(
    split: str = typer.Option("paper", "--split", help="paper, disjoint or timed."),
    form: str = typer.Option("lifted", "--form", help="lifted or grounded."),
    limit: int = typer.Option(0, "--limit",
                              help="Measure the sample an ablation with this --limit and "
                                   "--seed scores (0: the whole test side)."),
    seed: int = typer.Option(0, "--seed", help="Seed of that sample."),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON object."),
) -> None:
    """The accuracy the data set's own labels allow: where one sentence carries
    non-equivalent formulas, no translator can match them all."""
    from ara.data import load_split
    from ara.eval.ceiling import split_ceiling

    with user_errors():
        result = split_ceiling(load_split(split), form, limit, seed).to_dict()
    result.update(split=split, form=form, limit=limit or None, seed=seed)

    def text(d: dict) -> str:
        lines = [f"{d['split']} split, {d['form']} test records: {d['records']}",
                 f"  best any translator can do:      {d['oracle']} "
                 f"({100 * d['oracle_accuracy']:.2f}%)",
                 f"  a flawless learner of the train: {d['train_majority']} "
                 f"({100 * d['train_majority_accuracy']:.2f}%)",
                 f"  inputs with conflicting labels:  {len(d['conflicts'])}"]
        lines += [f"    {c['nl']!r}: test {c['test_labels']}, train's choice "
                  f"{c['train_choice']}" for c in d["conflicts"]]
        return "\n".join(lines)

    emit(result, as_json, text)
