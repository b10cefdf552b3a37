"""``ara translate`` and ``ara eval ...``: translate one sentence, run and score ablations."""

from __future__ import annotations

import json
import signal
from pathlib import Path
from typing import Literal

import typer

from ara.cli_support import emit, int_list, split_list, user_errors
from ara.data.handwritten import SUITES
from ara.data.store import FORMS
from ara.errors import ConfigError
from ara.eval.translate.answering import BUDGET_S
from ara.eval.translate.backends.openai_http import SERVERS
from ara.eval.translate.confidence import DOUBT
from ara.eval.translate.repair import DEFAULT_REPAIR, REPAIR_BY, REPAIR_HELP
from ara.eval.translate.repair import TEMPERATURE as REPAIR_TEMPERATURE
from ara.eval.translate.similar import EXAMPLES_BY as EXAMPLES_BY_VALUES

# Options with a fixed set of values: the help lists them, and typer refuses others.
ExamplesBy = Literal[EXAMPLES_BY_VALUES]
RepairBy = Literal[REPAIR_BY]
Server = Literal[SERVERS]
Form = Literal[FORMS]

eval_app = typer.Typer(
    help="Evaluate translators: one translation with every experimental option, the "
         "paper's ablation of few-shot examples (F), the grammar in the prompt (P) and "
         "constrained decoding (C) "
         "judged by Spot, and re-scoring, comparing and judging runs.",
    no_args_is_help=True)

MODEL_HELP = ("finetuned (the embedded Gemma 3 270M + its shipped LoRA), finetuned-paper (+ a "
              "LoRA of the paper split), default (no LoRA), lora:ADAPTER.gguf (yours), a "
              ".gguf path, hf:FOLDER or an http(s):// endpoint (#NAME: the model name sent; "
              "#chat:NAME: a chat model)")
SERVER_HELP = ("The server behind an http(s):// --model, which says where it reads a "
               "grammar: auto (asks it), or llama, vllm, sglang, openai (none).")


# The options ``ara translate`` and ``ara translate-file`` share, defined once.
MODEL = typer.Option("finetuned", "--model", help=MODEL_HELP)
SHOTS = typer.Option(
    None, "--shots", min=0, max=50,
    help="Worked examples in the prompt; default 0 for the fine-tuned adapters, 5 for "
         "other models.")
SEED = typer.Option(0, "--seed", help="Which worked examples, and the samples' seeds.")
EXAMPLES_BY = typer.Option(
    "random", "--examples-by",
    help="random (drawn with --seed) or similar (the pool's pairs worded most like the "
         "request, propositions aside).")
EXAMPLES = typer.Option(
    None, "--examples", dir_okay=False, exists=True,
    help="Your own pairs to take worked examples from (JSON Lines, each with \"stl\"); "
         "default: the training mixture.")
INTERVALS = typer.Option(
    True, "--intervals/--no-intervals",
    help="Allow time bounds (F[a,b], G[a,b], U[a,b]); an untimed sentence stays untimed.")
MAX_BOUND = typer.Option(1000, "--max-bound", min=1,
                         help="Largest time bound the grammar admits.")
ANY_BOUND = typer.Option(
    False, "--any-bound",
    help="Bounds up to --max-bound, not only 0 and the numbers the sentence writes.")
# Ranges are checked by RepairConfig, so every way in refuses a bad value alike.
TEMPERATURE = typer.Option(REPAIR_TEMPERATURE, "--temperature", help=REPAIR_HELP["temperature"])
REPAIR_OPTION = typer.Option(None, "--repair", help=REPAIR_HELP["samples"] + f" Default "
                             f"{DEFAULT_REPAIR}; 0: off.")
# ara eval translate votes and decodes freely, where repair is off by default.
EVAL_REPAIR_OPTION = typer.Option(
    None, "--repair", help=REPAIR_HELP["samples"] + f" Default {DEFAULT_REPAIR}, or 0 with "
    "--samples above 1 or --no-constraint; 0: off.")
REPAIR_BY_OPTION = typer.Option(REPAIR_BY[0], "--repair-by", help=REPAIR_HELP["by"])
DOUBT_OPTION = typer.Option(DOUBT, "--doubt", help=REPAIR_HELP["doubt"])
ALTERNATIVES = typer.Option(
    2, "--alternatives", min=0, max=8,
    help="Other readings to list when the model doubts its answer.")
SERVER = typer.Option("auto", "--server", help=SERVER_HELP)
# Checked by AnswerConfig, as the repair options are by RepairConfig.
BUDGET = typer.Option(
    BUDGET_S, "--budget", metavar="SECONDS",
    help="Time for the whole answer; then the best answer found so far is given. "
         "0: no limit.")


AS_JSON = typer.Option(False, "--json", help="Print one JSON object.")
APS = typer.Option(..., "--aps", help="Comma-separated propositions, each named in the "
                   "sentence (go_to_kitchen: 'go to the kitchen').")
NL = typer.Argument(..., metavar="INSTRUCTION",
                    help="The instruction, e.g. 'always avoid the door'.")


def translate_cmd(
    nl: str = NL,
    aps: str = APS,
    model: str = MODEL,
    shots: int | None = SHOTS,
    examples_by: ExamplesBy = EXAMPLES_BY,
    examples: Path | None = EXAMPLES,
    seed: int = SEED,
    intervals: bool = INTERVALS,
    max_bound: int = MAX_BOUND,
    any_bound: bool = ANY_BOUND,
    repair: int | None = REPAIR_OPTION,
    alternatives: int = ALTERNATIVES,
    budget: float = BUDGET,
    server: Server = SERVER,
    as_json: bool = AS_JSON,
) -> None:
    """Translate one instruction into STL over the given propositions.

    Prints the formula; on stderr, what it leaves out and, when the model doubts
    it, other readings. Experiments' knobs: `ara eval translate`.
    """
    _translate(nl, aps, model, shots, examples_by, examples, seed, intervals, max_bound,
               any_bound, repair=repair, alternatives=alternatives, budget_s=budget,
               server=server, as_json=as_json)


def eval_translate_cmd(
    nl: str = NL,
    aps: str = APS,
    model: str = MODEL,
    no_constraint: bool = typer.Option(False, "--no-constraint",
                                       help="Decode freely instead of under the grammar."),
    grammar_in_prompt: bool = typer.Option(False, "--grammar-in-prompt",
                                           help="Show the grammar in the prompt."),
    shots: int | None = SHOTS,
    examples_by: ExamplesBy = EXAMPLES_BY,
    examples: Path | None = EXAMPLES,
    seed: int = SEED,
    intervals: bool = INTERVALS,
    max_bound: int = MAX_BOUND,
    any_bound: bool = ANY_BOUND,
    samples: int = typer.Option(
        1, "--samples", min=1, max=32,
        help="Self-consistency: K answers under the grammar (greedy + K-1 sampled), "
             "grouped by Spot equivalence; the largest group wins. 1: greedy."),
    temperature: float = TEMPERATURE,
    repair: int | None = EVAL_REPAIR_OPTION,
    repair_by: RepairBy = REPAIR_BY_OPTION,
    doubt: float = DOUBT_OPTION,
    alternatives: int = ALTERNATIVES,
    budget: float = BUDGET,
    server: Server = SERVER,
    as_json: bool = AS_JSON,
) -> None:
    """`ara translate` with every knob of the experiments: self-consistency votes,
    the way repair searches, unconstrained decoding, the grammar in the prompt."""
    _translate(nl, aps, model, shots, examples_by, examples, seed, intervals, max_bound,
               any_bound, samples=samples, repair=repair, repair_by=repair_by, doubt=doubt,
               temperature=temperature, grammar_in_prompt=grammar_in_prompt,
               constrained=not no_constraint, alternatives=alternatives, budget_s=budget,
               server=server, as_json=as_json)


def _translate(nl: str, aps: str, model: str, shots: int | None, examples_by: str,
               examples: Path | None, seed: int, intervals: bool, max_bound: int,
               any_bound: bool, server: str, as_json: bool, **how) -> None:
    from ara.api import translate
    from ara.eval.translate.answering import notes

    with user_errors():  # the same path as ara.translate from Python
        answer = translate(nl, split_list(aps), model, shots=shots, seed=seed,
                           examples_by=examples_by, examples=examples,
                           intervals=intervals, max_bound=max_bound, any_bound=any_bound,
                           server=server, **how)
    for note in [] if as_json else notes(answer, nl):  # JSON users read the fields
        typer.echo(note, err=True)
    r = answer.result
    emit(answer.to_json(), as_json,
         lambda _: r.stl if r.valid else f"invalid: {r.error}\n{r.raw}")


def translate_file_cmd(
    requests: Path = typer.Argument(
        ..., help='JSON Lines, one request per line: {"nl": "...", "aps": ["a", "b"]}, '
                  'optionally "stl" (a reference, judged by Spot) and "id".'),
    out: Path = typer.Option(..., "--out", help="JSON Lines: each request with its answer "
                             "(the object of ara translate --json), written as it is made."),
    resume: bool = typer.Option(False, "--resume",
                                help="Go on with an --out an interrupted run left, made "
                                     "with the same options (kept beside it, in "
                                     "OUT with .settings.json for its suffix)."),
    model: str = MODEL,
    shots: int | None = SHOTS,
    examples_by: ExamplesBy = EXAMPLES_BY,
    examples: Path | None = EXAMPLES,
    seed: int = SEED,
    intervals: bool = INTERVALS,
    max_bound: int = MAX_BOUND,
    any_bound: bool = ANY_BOUND,
    repair: int | None = REPAIR_OPTION,
    alternatives: int = ALTERNATIVES,
    budget: float = BUDGET,
    spot_timeout: float = typer.Option(10.0, "--spot-timeout", min=0.1,
                                       help="Seconds per Spot check against a reference."),
    progress: bool = typer.Option(True, "--progress/--no-progress",
                                  help="Show a progress bar on stderr."),
    server: Server = SERVER,
    as_json: bool = typer.Option(False, "--json", help="Print the summary as JSON."),
) -> None:
    """Translate a file of instructions as ara translate would, loading the model once.

    Every line is checked first (a bad line stops the run before any
    translation, naming its line). Answers are appended to --out one line
    each as they are made, so an interrupted run loses nothing: rerun with
    --resume. At the end a summary: how many answers are valid, doubted
    (confidence below 0.5), leave part of the request out, and, for lines
    with a reference, how many are Spot-equivalent to it. Repair's other
    ways (--repair-by, --doubt) are in `ara eval ablation --data`.
    """
    from dataclasses import asdict

    from tqdm import tqdm

    from ara.eval.translate.answering import AnswerConfig, worked_examples
    from ara.eval.translate.batch import (
        check_out,
        done_lines,
        same_settings,
        summarize,
        summary_table,
        translate_requests,
    )
    from ara.eval.translate.models import shared_backend
    from ara.eval.translate.request_file import read_requests
    from ara.eval.translate.translator import Translator, TranslatorConfig

    with user_errors():
        config = TranslatorConfig(intervals=intervals, max_bound=max_bound,
                                  bounds_from_request=not any_bound)
        todo = read_requests(requests, config)
        how = AnswerConfig.of(repair=repair, seed=seed, alternatives=alternatives,
                              budget_s=budget)
        check_out(out, resume)
        translator = Translator(shared_backend(model, server=server), config)
        same_settings(out, {"model": translator.backend.model_id, "answer": asdict(how),
                            "translator": asdict(config), "shots": shots,
                            "examples_by": examples_by,
                            "examples": None if examples is None else str(examples)})
        done = done_lines(out, todo, translator.backend.model_id)

        def shots_for(nl: str, aps: tuple[str, ...]) -> list:  # as ara translate picks them
            return worked_examples(model, shots, aps, seed, nl, examples_by, examples)

        if done:
            typer.echo(f"resuming {out} after {done} of {len(todo)} answers", err=True)
        rows = translate_requests(translator, todo[done:], out, shots_for, how, spot_timeout)
        try:
            for _ in tqdm(rows, total=len(todo), initial=done, unit="request",
                          disable=not progress):
                pass
        except KeyboardInterrupt:
            kept = len(out.read_text(encoding="utf-8").splitlines())
            typer.echo(f"\ninterrupted: {kept} of {len(todo)} answers are in {out}; run the "
                       "same command with --resume to go on", err=True)
            raise typer.Exit(130) from None
    lines = [json.loads(line) for line in out.read_text(encoding="utf-8").splitlines()]
    summary = summarize(lines)
    emit(summary, as_json, lambda s: summary_table(s) + f"\n\nanswers in {out}")


eval_app.command("translate", short_help="ara translate with every experiment knob.")(
    eval_translate_cmd)


@eval_app.command("ablation", short_help="The paper's F/P/C ablation, judged by Spot.")
def ablation_cmd(
    out: Path = typer.Option(..., "--out", help="Run folder: samples.jsonl, results.json, ..."),
    split: str | None = typer.Option(
        None, "--split",
        help="paper (the default), disjoint, timed, compositional (held-out shapes and "
             f"phrasings) or a hand-written suite ({', '.join(SUITES)}; docs/data.md "
             "says which were read to guide what)."),
    data: Path | None = typer.Option(
        None, "--data", dir_okay=False,
        help="Your own pairs instead of a split: JSON Lines as `ara translate-file` reads, "
             'each line with its reference, e.g. {"nl": "never enter the lab", "aps": '
             '["enter_lab"], "stl": "G(!enter_lab)"}.'),
    examples: Path | None = typer.Option(
        None, "--examples", dir_okay=False,
        help="With --data: a file of pairs in the same format to draw worked examples "
             "from (lines whose sentence is a test are left out). Default: the "
             "compositional train side, in your lines' form."),
    form: Form | None = typer.Option(
        None, "--form",
        help="lifted (placeholder names prop_1, ...) or grounded (the sentence's own names) "
             "[default: lifted; with --data, every line]."),
    variants: str = typer.Option("F,F+P,F+P+C", "--variants",
                                 help="Comma list of variants: letters F, P, C joined by "
                                      "+, or none (zero-shot, unconstrained)."),
    shots: str = typer.Option("5,20", "--shots", help="Comma list of few-shot counts."),
    examples_by: ExamplesBy = typer.Option(
        "random", "--examples-by",
        help="How the F variants' worked examples are chosen: random (drawn with --seed, "
             "the same for every test pair of a rerun) or similar (for each test pair, "
             "the pool's pairs most like it; never one with the test's own sentence)."),
    reruns: int = typer.Option(3, "--reruns", min=1, help="Reruns, each with new examples."),
    limit: int = typer.Option(1000, "--limit", min=1, help="Test pairs to sample."),
    seed: int = typer.Option(0, "--seed", help="Seeds the test sample and the examples."),
    model: str = typer.Option("default", "--model", help=MODEL_HELP),
    mask: str = typer.Option("llguidance", "--mask", metavar="ENGINE",
                             help="Constraint engine of a local model: llguidance (fast, "
                                  "any), llama (llama.cpp's built-in, GGUF) or outlines "
                                  "(hf:); a server uses its own."),
    spot_timeout: float = typer.Option(10.0, "--spot-timeout", min=0.1,
                                       help="Seconds per Spot check before 'undecided'."),
    resume: bool = typer.Option(False, "--resume", help="Continue the run in --out."),
    progress: bool = typer.Option(True, "--progress/--no-progress",
                                  help="Show a progress bar on stderr."),
    server: Server = SERVER,
    concurrency: int = typer.Option(
        1, "--concurrency", min=1,
        help="Requests in flight at once, for an http(s):// --model (the server batches "
             "them); samples are still written in order, and --resume works as usual."),
    repair: int = typer.Option(0, "--repair", help="Constrained variants: "
                               + REPAIR_HELP["samples"] + " 0 (the paper's variants): greedy."),
    repair_by: RepairBy = REPAIR_BY_OPTION,
    doubt: float = DOUBT_OPTION,
) -> None:
    """Run the F/P/C ablation and write samples, results, tables and a plot to --out."""
    from ara.eval.ablation import load_data, run_ablation
    from ara.eval.harness import FILE_SPLIT, AblationConfig, plan
    from ara.eval.report import tables_markdown
    from ara.eval.translate.models import make_backend
    from ara.eval.translate.repair import RepairConfig

    # SIGTERM ends the run like Ctrl-C: finished samples stay, the report is written.
    signal.signal(signal.SIGTERM, signal.default_int_handler)
    with user_errors():
        if data is not None and split is not None:
            raise ConfigError("--split or --data: a run reads one split, or your own file")
        if examples is not None and data is None:
            raise ConfigError("--examples goes with --data; a split has its own train side")
        config = AblationConfig(
            split=FILE_SPLIT if data else split or "paper",
            form=form if form or data else "lifted",
            data=None if data is None else str(data),
            examples=None if examples is None else str(examples),
            variants=split_list(variants),
            shots=int_list(shots, "--shots"), reruns=reruns, limit=limit,
            seed=seed, model=model, spot_timeout_s=spot_timeout,
            repair=RepairConfig(repair, repair_by, doubt), examples_by=examples_by,
        )
        loaded = load_data(config)
        plan(config, loaded)  # a bad file or plan is named before the model loads
        backend = make_backend(model, mask=mask, server=server)
        try:
            results = run_ablation(config, backend, out, resume, progress=progress,
                                   concurrency=concurrency, split=loaded)
        except KeyboardInterrupt:
            typer.echo(f"interrupted: finished samples are in {out}; continue with --resume",
                       err=True)
            raise typer.Exit(130) from None
    typer.echo(tables_markdown(results))
    typer.echo(f"wrote {out}/samples.jsonl, results.json, tables.md, plot.png")


@eval_app.command("score", short_help="Re-score a run from its samples.")
def score_cmd(
    folder: Path = typer.Argument(..., help="A run folder from `ara eval ablation`."),
    as_json: bool = typer.Option(False, "--json", help="Print results.json instead of tables."),
) -> None:
    """Re-score a run from its samples.jsonl (no model needed) and rewrite its report."""
    from ara.eval.report import tables_markdown, write_report

    with user_errors():
        results = write_report(folder)
    emit(results, as_json, tables_markdown)


@eval_app.command("diff", short_help="What one run fixed and broke against another.")
def diff_cmd(
    before: Path = typer.Argument(..., help="A run folder from `ara eval ablation`."),
    after: Path = typer.Argument(..., help="Another run on the same data (a new model, "
                                           "setting or variant)."),
    show: int = typer.Option(10, "--show", min=0, help="Pairs listed of each kind."),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON object, every pair."),
) -> None:
    """Compare two runs answer by answer: fixed, broken, rewritten, the same (no model
    needed). Runs of one variant each are paired even when their variants differ."""
    from ara.eval.run_diff import diff_markdown, diff_runs

    with user_errors():
        result = diff_runs(before, after).to_dict()
    emit(result, as_json, lambda d: diff_markdown(d, show))


@eval_app.command("verdict", short_help="Release gate: may a candidate adapter ship?")
def verdict_cmd(
    folder: Path = typer.Argument(..., help="A judge's folder (scripts/judge_candidate.sh)."),
    judge: str = typer.Option(..., "--judge", help="The blind suite that judged the change."),
    max_drop: float = typer.Option(1.0, "--max-drop",
                                   help="Percentage points any other held-out set may fall "
                                        "below the shipped file."),
    help_misses: int = typer.Option(0, "--help-misses",
                                    help="Help requests the candidate may get wrong beyond "
                                         "the shipped file's."),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON object."),
) -> None:
    """Whether a judged candidate may replace the shipped adapter, check by check (no model
    needed). It ships when it is right on at least as many of the judge's answers as the
    shipped file (greedy and with repair), on no other held-out set more than --max-drop
    points below it, on at least as many help requests (less --help-misses), with every
    auction of Experiment 2 as the template's, and no more invalid answers. Writes
    verdict.json into FOLDER, which scripts/ship_adapter.py reads; exits 0 either way."""
    from ara.eval.verdict import ShippingRule, verdict, verdict_markdown
    from ara.provenance import write_atomic

    with user_errors():
        result = verdict(folder, judge, ShippingRule(max_drop, help_misses)).to_dict()
        write_atomic(folder / "verdict.json", json.dumps(result, indent=2) + "\n")
    emit(result, as_json, verdict_markdown)


@eval_app.command("ceiling", short_help="The accuracy a split's own labels allow.")
def ceiling_cmd(
    split: str = typer.Option("paper", "--split",
                              help="paper, disjoint, timed, compositional or a hand-written "
                                   "suite (handwritten, handwritten2, ...)."),
    form: Form = typer.Option("lifted", "--form", help="lifted or grounded."),
    limit: int = typer.Option(0, "--limit", min=0,
                              help="Measure only the N test pairs `ara eval ablation --limit N "
                                   "--seed S` samples (0: the whole test side)."),
    seed: int = typer.Option(0, "--seed", help="Seed of that sample."),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON object."),
) -> None:
    """The accuracy the data set's own labels allow: where one sentence carries
    non-equivalent formulas, no translator can match them all."""
    from ara.data import load_or_prepare
    from ara.eval.ceiling import split_ceiling

    with user_errors():
        result = split_ceiling(load_or_prepare(split), form, limit, seed).to_dict()
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
