"""Ship an exported adapter as a `--model` of the toolkit, after checking what users run.

    .venv/bin/python scripts/ship_adapter.py runs/recipe/gemma3-270m-nl2tl/export
    .venv/bin/python scripts/ship_adapter.py runs/train/gemma3-270m-lora \\
        --name gemma3-270m-nl2tl-paper-lora.gguf --split paper

EXPORT is the recipe's export stage, or a run folder that `ara export --lora-gguf` wrote
into (its `export/`). The adapter is copied into `eval/models/NAME` (and as PEFT into
`NAME-peft/`, which `init_adapter: finetuned` reads) beside a record of what produced it
(the run, the export with its parity, the held-out check) and the parity
of what a user runs: the embedded Q4_K_M base plus this adapter (llama.cpp) against the
merged fp32 model (transformers), greedy, on 20 lifted and 20 grounded test pairs. Below
`--min-agreement` nothing is shipped. Judge the candidate against the shipped file first
(`scripts/judge_candidate.sh EXPORT/lora.gguf SUITE`): the default file (`--model
finetuned`) ships only where that judge's `verdict.json` (found by the adapter's hash
under `runs/generalization/`, or given with `--verdict`) says it ships, or with
`--despite REASON`, which the record keeps beside the failed checks.
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
from pathlib import Path

from ara.errors import ConfigError

#: What a PEFT adapter folder needs, of what a run's ``adapter/`` holds.
PEFT_FILES = ("adapter_config.json", "adapter_model.safetensors")


def export_folders(path: Path) -> tuple[Path, Path]:
    """(the training run's record folder, the export folder) of ``path``."""
    export = path / "export" if (path / "export" / "lora.gguf").is_file() else path
    run = path if (path / "run.json").is_file() else export
    for need in (export / "lora.gguf", export / "export.json", export / "merged-hf",
                 run / "run.json", *(run / "adapter" / part for part in PEFT_FILES)):
        if not need.exists():
            raise ConfigError(f"{path}: no {need.name}; export the run first "
                              "(`ara export --run RUN --quant f16 --lora-gguf`)")
    return run, export


DEFAULT_NAME = "gemma3-270m-nl2tl-lora.gguf"


def judged(adapter: Path, given: Path | None, despite: str | None) -> dict:
    """What the record keeps of the judge of ``adapter``; raises where the rule stops it."""
    from ara.provenance import sha256_file

    if given is None:
        found = sorted(Path("runs/generalization").glob(
            f"judge-{sha256_file(adapter)[:8]}-*/verdict.json"))
        given = found[-1] if found else None
    if given is None or not given.is_file():
        if despite:
            return {"verdict": None, "despite": despite}
        raise ConfigError(f"no verdict for {adapter}: judge it first (scripts/"
                          "judge_candidate.sh), or ship it --despite REASON")
    result = json.loads(given.read_text())
    if not result["ships"] and not despite:
        failed = "; ".join(f"{c['name']}: {c['why']}" for c in result["checks"]
                           if not c["passed"])
        raise ConfigError(f"{given} says it does not ship ({failed}); --despite REASON "
                          "overrides it, and the record keeps the reason")
    return {"verdict": {"file": str(given), **result}, "despite": despite}


def ship(path: Path, name: str, split: str, min_agreement: float, pairs: int = 20,
         judge: dict | None = None) -> dict:
    from ara.data import load_or_prepare
    from ara.eval.translate.llama_check import default_model_path
    from ara.eval.translate.models import SHIPPED
    from ara.provenance import sha256_file
    from ara.training.export import parity

    run, export = export_folders(path)
    data = load_or_prepare(split, 0)
    records = data.records("test", "lifted")[:pairs] + data.records("test", "grounded")[:pairs]
    checked = parity(Path(default_model_path()), export / "merged-hf", records,
                     lora=export / "lora.gguf")
    if checked["agreement"] < min_agreement:
        raise ConfigError(f"the Q4_K_M base with this adapter agrees with the merged model on "
                          f"{checked['agree']} of {checked['pairs']} pairs, below "
                          f"{min_agreement:.0%}: not shipped")
    target = SHIPPED / name
    shutil.copyfile(export / "lora.gguf", target)
    # The same weights as PEFT, which a warm start from the shipped file reads
    # (`init_adapter: finetuned`): the two must never come from different runs.
    peft = SHIPPED / f"{target.stem}-peft"
    peft.mkdir(exist_ok=True)
    for part in PEFT_FILES:
        shutil.copyfile(run / "adapter" / part, peft / part)
    heldout = run / "heldout.json"
    manifest = {"file": name, "sha256": sha256_file(target),
                "run": json.loads((run / "run.json").read_text()),
                "export": json.loads((export / "export.json").read_text()),
                # A soup was never trained as a whole: no held-out check of its own.
                "heldout": json.loads(heldout.read_text()) if heldout.is_file() else None,
                "shipped_parity": {
                    "what": "embedded Q4_K_M GGUF + this adapter (llama.cpp) vs the merged HF "
                            f"model (transformers, fp32), greedy, zero-shot, unconstrained; "
                            f"{pairs} lifted + {pairs} grounded {split} test pairs",
                    **checked},
                "judged": judge}
    target.with_suffix(".json").write_text(json.dumps(manifest, indent=2) + "\n")
    return manifest


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("export", type=Path, help="the export stage, or an exported run folder")
    parser.add_argument("--name", default=DEFAULT_NAME,
                        help="file name in eval/models/ (default: the --model finetuned one)")
    parser.add_argument("--split", default="compositional",
                        help="split whose test pairs the parity check reads")
    parser.add_argument("--min-agreement", type=float, default=0.9,
                        help="ship only when at least this share of greedy answers agree")
    parser.add_argument("--verdict", type=Path,
                        help="the judge's verdict.json (default: found by the adapter's hash)")
    parser.add_argument("--despite", metavar="REASON",
                        help="ship the default file although its verdict says no (or it has "
                             "none); the record keeps REASON")
    args = parser.parse_args(argv)
    try:
        judge = None
        if args.name == DEFAULT_NAME:
            judge = judged(export_folders(args.export)[1] / "lora.gguf", args.verdict,
                           args.despite)
        manifest = ship(args.export, args.name, args.split, args.min_agreement, judge=judge)
    except ConfigError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    print(json.dumps({k: manifest[k] for k in ("file", "sha256")}
                     | {"parity": manifest["shipped_parity"]["agreement"]}, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
