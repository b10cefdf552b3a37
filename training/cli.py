"""``ara model ...``: base models for fine-tuning and the Hugging Face backend."""

from __future__ import annotations

from pathlib import Path

import typer

from ara.cli_support import user_errors

model_app = typer.Typer(help="Prepare base models (no downloads).", no_args_is_help=True)


@model_app.command("prepare")
def prepare_cmd(
    out: Path = typer.Option(None, "--out",
                             help="Target folder [default: ~/.cache/ara/models/gemma-3-270m-hf]."),
    gguf: str = typer.Option(None, "--gguf", help="GGUF to convert [default: embedded 270M]."),
    force: bool = typer.Option(False, "--force", help="Convert again even if done."),
) -> None:
    """Convert the embedded Gemma 3 270M GGUF into a local HF folder, once (~2 min)."""
    from ara.training.hf_model import prepare_base_model

    with user_errors():
        folder = prepare_base_model(out, gguf, force)
    typer.echo(str(folder))


def train_cmd(
    config: Path = typer.Option(..., "--config",
                                help="A run config, e.g. training/configs/*.yaml."),
    max_steps: int = typer.Option(None, "--max-steps", help="Stop after N optimizer steps."),
    resume: bool = typer.Option(False, "--resume", help="Continue from the newest checkpoint."),
) -> None:
    """LoRA fine-tuning (transformers + peft + accelerate) with the eval prompt format."""
    import json

    from ara.training.recipe import main

    with user_errors():
        summary = main(str(config), max_steps, resume)
    typer.echo(json.dumps(summary, indent=2))


def soup_cmd(
    runs: list[Path] = typer.Option(..., "--run",
                                    help="A finished `ara train` run folder (twice or more)."),
    weights: list[float] = typer.Option(
        None, "--weight", help="One weight per --run, in order (default: all equal)."),
    out: Path = typer.Option(..., "--out", help="The soup's run folder (adapter/, run.json)."),
    rank: int = typer.Option(
        None, "--rank", min=1,
        help="Truncate the result to this rank by SVD (the parts' ranks add up, and a "
             "higher rank is slower at every token). With --rank, one --run is enough: "
             "that run's adapter, reduced."),
) -> None:
    """Average the adapters of runs that grew from one start into one exact LoRA adapter.

    The result is a run folder like any other: `ara export --run OUT --lora-gguf` turns
    it into a GGUF LoRA for `ara translate --model lora:OUT/export/lora.gguf`.
    """
    import json

    from ara.errors import ConfigError
    from ara.training.soup import SoupPart, average_adapters, reduce_rank

    with user_errors():
        weights = weights or [1.0] * len(runs)
        if len(weights) != len(runs):
            raise ConfigError(f"{len(weights)} --weight values for {len(runs)} --run folders")
        if len(runs) < 2 and rank is None:
            raise ConfigError("a soup needs at least two --run folders (or one and --rank)")
        for run in runs:
            if not (run / "run.json").is_file():
                raise ConfigError(f"{run} is not an `ara train` run folder (no run.json)")
        # The first run's record (base model, data version) is what export needs; the
        # soup's own parts say where the weights came from.
        record = json.loads((runs[0] / "run.json").read_text())
        adapter = out / "adapter"
        if len(runs) > 1:
            parts = [SoupPart(run / "adapter", w) for run, w in zip(runs, weights, strict=True)]
            record["soup"] = average_adapters(parts, adapter)
        if rank is not None:
            record["reduced"] = reduce_rank(adapter if len(runs) > 1 else runs[0] / "adapter",
                                            rank, adapter)
        out.mkdir(parents=True, exist_ok=True)
        (out / "run.json").write_text(json.dumps(record, indent=2) + "\n")
    typer.echo(json.dumps({k: record[k] for k in ("soup", "reduced") if k in record},
                          indent=2))


def export_cmd(
    run: Path = typer.Option(..., "--run", help="A finished `ara train` run folder."),
    quant: str = typer.Option("f16,q8_0,q4_k_m", "--quant",
                              help="Comma list of GGUF types: f32, f16, q8_0, q4_k_m, ..."),
    lora_gguf: bool = typer.Option(False, "--lora-gguf", help="Also the adapter as GGUF LoRA."),
    parity_pairs: int = typer.Option(20, "--parity",
                                     help="Test pairs for the GGUF vs HF greedy check (0: skip)."),
) -> None:
    """Merge the adapter into the base, convert to GGUF, quantize, check parity."""
    import json

    from ara.cli_support import split_list
    from ara.training.export import export_run, parity

    with user_errors():
        quants = split_list(quant)
        outtype = "f32" if "f32" in quants else "f16"
        manifest = export_run(run, quants, lora_gguf, outtype)
        if parity_pairs:
            from ara.data import load_split

            saved = json.loads((run / "run.json").read_text())
            config = saved["config"]
            # The version the run trained on, which run.json records
            records = load_split(config["data"]["split"], config["data"]["seed"],
                                 version=saved["data"]["version"]).records(
                "test", config["data"]["forms"][0])[:parity_pairs]
            export = run / "export"
            manifest["parity"] = parity(export / f"model-{outtype}.gguf", export / "merged-hf",
                                        records)
            (export / "export.json").write_text(json.dumps(manifest, indent=2) + "\n")
    typer.echo(json.dumps(manifest, indent=2))
