"""``ara``: the toolkit's command line. It composes each area's commands; no logic here."""

from __future__ import annotations

import warnings

import typer

from ara import __version__
from ara.coordination.cli import coord_app
from ara.data.cli import data_app
from ara.demo import demo_cmd
from ara.eval.cli import eval_app, translate_cmd, translate_file_cmd
from ara.grammars.cli import grammar_cmd, stl_app
from ara.training.cli import export_cmd, model_app, soup_cmd, train_cmd

app = typer.Typer(
    # Plain help: rich's panels wrap each option's help into a narrow column, several
    # screens for ara translate.
    rich_markup_mode=None,
    context_settings={"help_option_names": ["-h", "--help"]},
    help="ask-reason-assist: natural language to Signal Temporal Logic with guaranteed "
         "syntax, for multi-robot help requests.",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
)
app.add_typer(stl_app, name="stl", short_help="Parse, explain and compare formulas.")
app.add_typer(data_app, name="data", short_help="Prepare, inspect and export data splits.")
app.add_typer(eval_app, name="eval", short_help="Ablations, scores, diffs, release verdicts.")
app.add_typer(model_app, name="model", short_help="Prepare base models (no downloads).")
app.add_typer(coord_app, name="coord", short_help="Help requests, planning, Experiment 2.")
app.command("translate", short_help="One instruction to STL.")(translate_cmd)
app.command("translate-file", short_help="A file of instructions to STL (resumable).")(
    translate_file_cmd)
app.command("grammar", short_help="Print a decoding grammar (GBNF or Lark).")(grammar_cmd)
app.command("demo", short_help="The main job on the embedded defaults.")(demo_cmd)
app.command("train", short_help="LoRA fine-tuning from a recipe config.")(train_cmd)
app.command("export", short_help="Merge, convert to GGUF, quantize, check.")(export_cmd)
app.command("soup", short_help="Average the LoRA adapters of runs.")(soup_cmd)


def _note(message, category, filename, lineno, file=None, line=None) -> str:
    """Warnings from our own code read as notes on the command line, not source lines."""
    if category.__module__.startswith("ara."):
        return f"note: {message}\n"
    return _default_format(message, category, filename, lineno, line)


_default_format = warnings.formatwarning
warnings.formatwarning = _note


def _version(value: bool) -> None:
    if value:
        typer.echo(f"ara {__version__}")
        raise typer.Exit()


@app.callback()
def main(
    version: bool = typer.Option(False, "--version", callback=_version, is_eager=True,
                                 help="Print the version and exit."),
) -> None:
    """Run `ara COMMAND --help` for each command's options."""


if __name__ == "__main__":
    app()
