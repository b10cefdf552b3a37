"""``ara data ...``: prepare, inspect and export the versioned splits."""

from __future__ import annotations

from pathlib import Path
from typing import Literal

import typer

from ara.cli_support import emit, user_errors
from ara.data.handwritten import SUITES
from ara.data.store import FORMS, SPLITS, load_or_prepare, prepare, to_hf

data_app = typer.Typer(help="Prepare, inspect and export the versioned NL2TL splits.",
                       no_args_is_help=True)

ROOT_OPT = typer.Option(None, "--root", file_okay=False,
                        help="Folder of prepared splits [default: $ARA_DATA_DIR, else "
                             "data/prepared].")


@data_app.command("prepare", short_help="Normalize, split and version a data set.")
def prepare_cmd(
    split: list[str] = typer.Option(
        list(SPLITS), "--split", metavar="SPLIT", show_default=False,
        help="paper (random 4,500/3,000 rows of NL2TL's navigation set), disjoint (no "
             "lifted formula on both sides), timed (NL2TL's own train/dev), compositional "
             "(the training mixture and its held-out shapes and phrasings), "
             f"{', '.join(SUITES)} (the hand-written suites, test only). Repeat for "
             "several [default: all].",
    ),
    seed: int = typer.Option(0, "--seed",
                             help="Shuffle seed (timed ignores it); ara eval reads seed 0's "
                                  "splits, a training config its data.seed's."),
    root: Path = ROOT_OPT,
    as_json: bool = typer.Option(False, "--json", help="Print the manifests as JSON lines."),
) -> None:
    """Normalize the raw data, split it, and write each split with its manifest."""
    for name in split:
        with user_errors():
            prepared = prepare(name, seed, root)
        m = prepared.manifest
        emit(m, as_json, lambda m, folder=prepared.folder: (
            f"{folder}  version {m['version']}: "
            + ", ".join(f"{p} {sum(c.values())} records" for p, c in m["counts"].items())
            + f"; {m['rejected']['count']} raw rows rejected"
            + "".join(f"\n    rejected row {e['row']}: {e['text']!r}: {e['error']}"
                      for e in m["rejected"]["examples"][:3])
        ))


@data_app.command("stats", short_help="Counts and rejected rows of a split.")
def stats_cmd(
    split: list[str] = typer.Option(list(SPLITS), "--split", metavar="SPLIT", show_default=False,
                                    help="A split to describe; repeat for several "
                                         "[default: all]."),
    seed: int = typer.Option(0, "--seed", help="Seed the splits were prepared with."),
    root: Path = ROOT_OPT,
    as_json: bool = typer.Option(False, "--json", help="Print JSON lines."),
) -> None:
    """Record counts, rejected rows and train/test overlap of the splits (each prepared
    first if this machine lacks it: deterministic, versioned, seconds)."""
    rows = []
    for name in split:
        with user_errors():
            m = load_or_prepare(name, seed, root).manifest
        for form, o in m["overlap"].items():
            rows.append({
                "split": name, "version": m["version"], "form": form,
                "train": m["counts"]["train"][form], "test": m["counts"]["test"][form],
                "rejected_rows": m["rejected"]["count"],
                "test_formula_seen": o["formula_seen"], "test_nl_seen": o["nl_seen"],
            })
    if as_json:
        for row in rows:
            emit(row, True)
        return
    header = ("split", "version", "form", "train", "test", "rejected_rows",
              "test_formula_seen", "test_nl_seen")
    typer.echo("| " + " | ".join(header) + " |")
    typer.echo("|" + "---|" * len(header))
    for row in rows:
        typer.echo("| " + " | ".join(_cell(row[h]) for h in header) + " |")


def _cell(value) -> str:
    return f"{value:.1%}" if isinstance(value, float) else str(value)


@data_app.command("export", short_help="A split as a Hugging Face DatasetDict.")
def export_cmd(
    out: Path = typer.Option(..., "--out", file_okay=False,
                             help="Folder to write the Hugging Face dataset to."),
    split: str = typer.Option("paper", "--split", help="Split to export."),
    seed: int = typer.Option(0, "--seed", help="Seed it was prepared with."),
    form: Literal[FORMS] | None = typer.Option(None, "--form",
                             help="lifted (placeholder names prop_1, prop_2, ...) or grounded "
                                  "(the sentence's own names) [default: both]."),
    root: Path = ROOT_OPT,
) -> None:
    """Save a prepared split as a Hugging Face ``datasets`` DatasetDict (save_to_disk)."""
    with user_errors():
        dataset = to_hf(load_or_prepare(split, seed, root), form)
        dataset.save_to_disk(str(out))
    typer.echo(f"wrote {out} ({', '.join(f'{k}: {len(v)}' for k, v in dataset.items())})")

