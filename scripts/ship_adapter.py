"""Ship an exported adapter as a `--model` of the toolkit, after checking what users run.

    .venv/bin/python scripts/ship_adapter.py runs/recipe/gemma3-270m-nl2tl/export
    .venv/bin/python scripts/ship_adapter.py runs/train/gemma3-270m-lora \\
        --name gemma3-270m-nl2tl-paper-lora.gguf --split paper --despite "judged by Table I"

EXPORT is the recipe's export stage, or a run folder that `ara export --lora-gguf` wrote
into (its `export/`). The adapter is copied into `eval/models/NAME` (a warm start from it,
`init_adapter: finetuned`, converts it back to PEFT) beside a record of what produced it
(the run, the recipe's record of every stage, the export with its parity, the held-out
check) and the parity of what a user runs: the embedded Q4_K_M base plus this adapter
(llama.cpp) against the merged fp32 model (transformers), greedy, on 20 lifted and 20
grounded test pairs. Below
`--min-agreement` nothing is shipped. Judge the candidate against the shipped file first
(`scripts/judge_candidate.sh EXPORT/lora.gguf SUITE`): a shipped file is replaced only
where that judge's `verdict.json` (`runs/generalization/judge-C-S-V/`, named by both
files' hashes and the data version, or given with `--verdict`) says the candidate ships
by the default rule, or with `--despite REASON`, which the record keeps beside the
verdict.
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
from pathlib import Path

from ara.errors import AraError, ConfigError
from ara.eval.translate.models import FINETUNED_LORA


def export_folders(path: Path) -> tuple[Path, Path]:
    """(the training run's record folder, the export folder) of ``path``."""
    export = path / "export" if (path / "export" / "lora.gguf").is_file() else path
    run = path if (path / "run.json").is_file() else export
    for need in (export / "lora.gguf", export / "export.json", export / "merged-hf",
                 run / "run.json"):
        if not need.exists():
            raise ConfigError(f"{path}: no {need.name}; export the run first "
                              "(`ara export --run RUN --quant f16 --lora-gguf`)")
    return run, export


def recipe_record(export: Path) -> dict | None:
    """The record of the staged recipe whose export stage is ``export`` (each stage's
    fingerprint, steps, wall time and memory), where it exported this very file: a
    soup's ``run.json`` holds only one part's config, so it cannot say how the file was
    made."""
    from ara.provenance import sha256_file

    path = export.parent / "recipe.json"
    if not path.is_file():
        return None
    record = json.loads(path.read_text())
    files = record.get("stages", {}).get("export", {}).get("result", {}).get("files", {})
    made = files.get("lora.gguf", {}).get("sha256")
    return record if made == sha256_file(export / "lora.gguf") else None


REPO = Path(__file__).resolve().parents[1]
DEFAULT_NAME = FINETUNED_LORA.name


def judged(adapter: Path, target: Path, given: Path | None, despite: str | None) -> dict:
    """What the record keeps of the judge of ``adapter`` against ``target``, the file it
    replaces; raises where the shipping rule stops it and no reason overrides it."""
    from dataclasses import asdict

    from ara.data import registered_version
    from ara.eval.verdict import ShippingRule
    from ara.provenance import sha256_file

    # The judge's folder names both files and the data it judged on: a verdict against
    # an earlier shipped file, or another candidate's, says nothing about this one.
    expected = (f"judge-{sha256_file(adapter)[:8]}-{sha256_file(target)[:8]}-"
                f"{registered_version('compositional')}")
    given = given or REPO / "runs" / "generalization" / expected / "verdict.json"
    # A committed record names paths as a clone sees them, not as this checkout lies.
    resolved = given.resolve()
    shown = resolved.relative_to(REPO) if resolved.is_relative_to(REPO) else given
    result, problem = None, None
    if not given.is_file():
        problem = f"no verdict {shown}: judge the candidate first (scripts/judge_candidate.sh)"
    else:
        result = json.loads(given.read_text())
        if result.get("folder") != expected:
            problem = f"{shown} judged {result.get('folder')}, not {expected}"
        elif result["rule"] != asdict(ShippingRule()):
            problem = f"{shown} was checked by another rule than the default: {result['rule']}"
        elif not result["ships"]:
            failed = "; ".join(f"{c['name']}: {c['why']}" for c in result["checks"]
                               if not c["passed"])
            problem = f"{shown} says it does not ship ({failed})"
    if problem and not despite:
        raise ConfigError(f"{problem}; --despite REASON overrides it, and the record keeps "
                          "the reason")
    return {"verdict_file": str(shown), "verdict": result, "problem": problem,
            "despite": despite}


def ship(path: Path, name: str, split: str, min_agreement: float, pairs: int = 20,
         judge: dict | None = None) -> dict:
    from ara.data import load_or_prepare
    from ara.eval.translate.models import SHIPPED, default_model_path
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
    heldout = run / "heldout.json"
    manifest = {"file": name, "sha256": sha256_file(target),
                "run": json.loads((run / "run.json").read_text()),
                "recipe": recipe_record(export),
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
                        help="the judge's verdict.json (default: the judge folder named by "
                             "both hashes)")
    parser.add_argument("--despite", metavar="REASON",
                        help="replace the shipped file although the verdict says no (or there "
                             "is none); the record keeps REASON")
    args = parser.parse_args(argv)
    try:
        from ara.eval.translate.models import SHIPPED

        judge, target = None, SHIPPED / args.name
        if target.is_file():  # replacing a shipped file: only as the judge allows
            judge = judged(export_folders(args.export)[1] / "lora.gguf", target, args.verdict,
                           args.despite)
        manifest = ship(args.export, args.name, args.split, args.min_agreement, judge=judge)
    except (AraError, FileNotFoundError, PermissionError) as error:  # what a user can fix
        print(f"error: {error}", file=sys.stderr)
        return 2
    print(json.dumps({k: manifest[k] for k in ("file", "sha256")}
                     | {"parity": manifest["shipped_parity"]["agreement"]}, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
