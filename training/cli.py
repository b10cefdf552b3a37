"""``ara model ...``: base models for fine-tuning and the Hugging Face backend."""

from __future__ import annotations

from pathlib import Path

import typer

from ara.cli_support import user_errors
from ara.errors import ConfigError
from ara.training.export import PARITY_PAIRS

model_app = typer.Typer(help="Prepare base models (no downloads).", no_args_is_help=True)


@model_app.command("prepare", short_help="The embedded GGUF as a local HF folder.")
def prepare_cmd(
    out: Path = typer.Option(None, "--out",
                             help="The folder to write, new or an earlier conversion (it "
                                  "is replaced whole) "
                                  "[default: ~/.cache/ara/models/gemma-3-270m-hf]."),
    gguf: str = typer.Option(None, "--gguf", help="GGUF to convert [default: embedded 270M]."),
    force: bool = typer.Option(False, "--force", help="Convert again even if done."),
) -> None:
    """Convert the embedded Gemma 3 270M GGUF into a local HF folder, once (~2 min): what
    hf: models and ara train load (ara train converts it itself when it is missing)."""
    from ara.training.hf_model import prepare_base_model

    with user_errors():
        folder = prepare_base_model(out, gguf, force)
    typer.echo(str(folder))


def train_cmd(
    config: Path = typer.Option(..., "--config",
                                help="A run config, or a staged recipe (a config with "
                                     "`stages:`), e.g. training/configs/gemma3_270m_nl2tl.yaml."),
    max_steps: int = typer.Option(
        None, "--max-steps", min=1,
        help="Stop after N optimizer steps, for a smoke run (in a recipe: each training "
             "stage; a later run without the flag trains those stages again)."),
    resume: bool = typer.Option(
        False, "--resume",
        help="Continue a single run from its newest checkpoint (a recipe always goes on "
             "where it stopped)."),
    status: bool = typer.Option(
        False, "--status",
        help="Train nothing: show where a staged recipe stands (what a rerun would do "
             "with each stage, steps done, hours left at the logged pace)."),
    as_json: bool = typer.Option(False, "--json", help="With --status: one JSON object."),
) -> None:
    """LoRA fine-tuning (transformers + peft + accelerate) with the eval prompt format.

    A staged recipe runs its stages in order (train, soup, export), each into a folder
    named after it under the recipe's `out:`;
    rerun the same command to go on after an interruption: done stages are skipped, an
    interrupted one resumes, and a stage whose settings changed is rebuilt with the
    stages after it. recipe.json there records each stage's wall time and peak memory.
    """
    import json
    import signal

    from ara.training.recipe import main

    with user_errors():
        if as_json and not status:
            raise ConfigError("--json goes with --status (a run prints its summary as JSON)")
        if status:
            if resume:
                raise ConfigError("--status trains nothing: leave out --resume")
            _print_status(config, max_steps, as_json)
            return

    # A scheduler, `timeout` or `kill` stops a run with SIGTERM: it now ends as Ctrl-C
    # does, so a recipe records the time the stage took and the log ends on a whole line.
    terminated = []

    def stop(signum, frame):
        terminated.append(signum)
        raise KeyboardInterrupt

    before = signal.signal(signal.SIGTERM, stop)
    try:
        with user_errors():
            summary = main(str(config), max_steps, resume)
    except KeyboardInterrupt:
        typer.echo("interrupted: rerun the same command (a single run with --resume) to go "
                   "on from the newest checkpoint", err=True)
        raise typer.Exit(143 if terminated else 130) from None
    finally:
        signal.signal(signal.SIGTERM, before)
    typer.echo(json.dumps(summary, indent=2))


def _print_status(config: Path, max_steps: int | None, as_json: bool) -> None:
    from ara.cli_support import emit
    from ara.training.config import read_config
    from ara.training.stage_runner import recipe_status
    from ara.training.stages import StagedRecipe, is_staged

    data = read_config(config)
    if not is_staged(data):
        raise ConfigError(f"{config} is a single run, not a staged recipe: its progress is "
                          "in OUT/train_log.jsonl (a line a step) and OUT/checkpoints/")
    emit(recipe_status(StagedRecipe.from_dict(data), max_steps), as_json, _status_table)


def _status_table(status: dict) -> str:
    lines = [status["out"] + (" (an ara train is running on it now)" if status["running"]
                              else ""),
             "| stage | kind | steps | state: what a rerun does |", "|---|---|---:|---|"]
    for row in status["stages"]:
        steps = "" if row["kind"] != "train" else f"{row['steps_done']:,} / " + (
            "?" if row["steps_total"] is None else f"{row['steps_total']:,}")
        lines.append(f"| {row['name']} | {row['kind']} | {steps} | {row['state']} |")
    left = f"{status['steps_left']:,}" + (" or more" if status["steps_left_unknown"] else "")
    pace = status["seconds_per_step"]
    if pace is None:
        lines.append(f"\n{left} training steps left (no step logged yet to time them)")
    else:
        lines.append(f"\n{left} training steps left: about {status['hours_left']:.1f} h at "
                     f"{pace:.1f} s a step (the median of the last 200 logged here), besides "
                     "held-out checks, soups and the export")
    return "\n".join(lines)


def soup_cmd(
    runs: list[Path] = typer.Option(..., "--run", metavar="RUN_DIR",
                                    help="A finished `ara train` run folder (twice or more)."),
    weights: list[float] = typer.Option(
        None, "--weight", metavar="W", help="One weight per --run, in order (default: all equal)."),
    out: Path = typer.Option(..., "--out", help="The soup's run folder (adapter/, run.json)."),
    rank: int = typer.Option(
        None, "--rank", min=1,
        help="Truncate the result to this rank by SVD (the parts' ranks add up, and a "
             "higher rank is slower at every token). With --rank, one --run is enough: "
             "that run's adapter, reduced."),
) -> None:
    """Average the LoRA adapters of runs trained from one starting point, exactly: the
    result is one LoRA adapter whose rank is the sum of theirs (see --rank).

    The result is a run folder like any other: `ara export --run OUT --lora-gguf` turns
    it into a GGUF LoRA for `ara translate --model lora:OUT/export/lora.gguf`.
    """
    import json

    from ara.training.soup import soup_runs

    with user_errors():
        record = soup_runs(runs, weights, out, rank)
    typer.echo(json.dumps({k: record[k] for k in ("soup", "reduced") if k in record},
                          indent=2))


def export_cmd(
    run: Path = typer.Option(..., "--run", help="A finished `ara train` run folder."),
    quant: str = typer.Option("f16,q8_0,q4_k_m", "--quant",
                              help="Comma list of GGUF types: f32, f16, q8_0, q4_k_m, ..."),
    lora_gguf: bool = typer.Option(False, "--lora-gguf", help="Also the adapter as GGUF LoRA."),
    parity_pairs: int = typer.Option(PARITY_PAIRS, "--parity",
                                     help="Test pairs for the GGUF vs HF greedy check (0: skip)."),
) -> None:
    """Merge the adapter into the base, convert to GGUF, quantize and check parity, into
    RUN/export/. The converter is llama.cpp's, from PyPI, fetched on first use."""
    import json

    from ara.cli_support import split_list
    from ara.training.export import export_checked

    with user_errors():
        manifest = export_checked(run, split_list(quant), lora_gguf, parity_pairs)
    typer.echo(json.dumps(manifest, indent=2))
