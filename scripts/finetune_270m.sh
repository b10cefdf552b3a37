#!/usr/bin/env bash
# The shipped fine-tune, end to end, on a CPU (about 50 min of training on 2 cores, then
# export and the README's evaluation runs, about 40 min more).
#
#   scripts/finetune_270m.sh [STEP ...]     steps: train export ship eval (default: all)
#
# Each step can be rerun alone; `train` resumes from its newest checkpoint if the run
# folder exists.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=.venv/bin
run=runs/train/gemma3-270m-lora
steps=${*:-train export ship eval}

for step in $steps; do
  case $step in
  train)
    if [ -f "$run/run.json" ]; then resume=--resume; else resume=; fi
    $bin/ara train --config training/configs/gemma3_270m_lora_cpu.yaml $resume ;;
  export)
    # f16 GGUF of the merged model + the adapter alone as a GGUF LoRA; parity on 20 pairs
    $bin/ara export --run "$run" --quant f16 --lora-gguf --parity 20 ;;
  ship)
    cp "$run/export/lora.gguf" eval/models/gemma3-270m-nl2tl-lora.gguf
    $bin/python - "$run" <<'PY'
import json, sys
from pathlib import Path
from ara.provenance import sha256_file
run = Path(sys.argv[1])
manifest = {"file": "gemma3-270m-nl2tl-lora.gguf",
            "sha256": sha256_file(Path("eval/models/gemma3-270m-nl2tl-lora.gguf")),
            "run": json.loads((run / "run.json").read_text()),
            "export": json.loads((run / "export" / "export.json").read_text()),
            "heldout": json.loads((run / "heldout.json").read_text())}
# What a user runs: the adapter on the embedded Q4_K_M base, against the merged HF model
from ara.data import load_split
from ara.eval.models import FINETUNED_LORA
from ara.grammars.llama_check import default_model_path
from ara.training.export import parity
split = load_split("paper", 0)
records = split.records("test", "lifted")[:20] + split.records("test", "grounded")[:20]
manifest["shipped_parity"] = {
    "what": "embedded Q4_K_M GGUF + this adapter (llama.cpp) vs the merged HF model "
            "(transformers, fp32), greedy, zero-shot, unconstrained; 20 lifted + 20 "
            "grounded paper test pairs",
    **parity(Path(default_model_path()), run / "export" / "merged-hf", records,
             lora=FINETUNED_LORA)}
Path("eval/models/gemma3-270m-nl2tl-lora.json").write_text(json.dumps(manifest, indent=2) + "\n")
PY
    ;;
  eval)
    for split in paper disjoint; do
      $bin/ara eval ablation --out "docs/results/finetuned-270m-$split" --split "$split" \
        --model finetuned --variants none,C,F,F+P,F+P+C --shots 5 --reruns 1 --limit 200 --resume
      $bin/ara eval ablation --out "docs/results/base-270m-$split-zeroshot" --split "$split" \
        --model default --variants none,C --shots 5 --reruns 1 --limit 200 --resume
    done ;;
  *) echo "unknown step $step (train export ship eval)" >&2; exit 2 ;;
  esac
done
