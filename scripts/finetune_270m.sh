#!/usr/bin/env bash
# The shipped fine-tune, end to end, on a CPU: about 65 min of training on 2 cores,
# then export and the README's evaluation runs (about 20 min); `disjoint` adds a
# held-out adapter trained on the disjoint split (about 30 min).
#
#   scripts/finetune_270m.sh [STEP ...]   steps: train export ship eval disjoint full
#                                         (default: train export ship eval)
#
# `full` scores the shipped adapter zero-shot under the grammar on the whole paper test
# side (2,989 lifted pairs, about 20 min).
#
# Each step can be rerun alone; training resumes from its newest checkpoint and the
# evaluations from their finished samples.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=.venv/bin
run=runs/train/gemma3-270m-lora
disjoint_run=runs/train/gemma3-270m-lora-disjoint
steps=${*:-train export ship eval}

train() {  # CONFIG RUN_FOLDER
  if [ -f "$2/run.json" ]; then resume=--resume; else resume=; fi
  $bin/ara train --config "$1" $resume
}

ablation() {  # SPLIT MODEL OUT VARIANTS [LIMIT]
  $bin/ara eval ablation --split "$1" --model "$2" --out "$3" --variants "$4" \
    --shots 5 --reruns 1 --limit "${5:-200}" --resume --no-progress
}

for step in $steps; do
  case $step in
  train)
    train training/configs/gemma3_270m_lora_cpu.yaml "$run" ;;
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
    ablation paper finetuned docs/results/finetuned-270m-paper none,C,F,F+P,F+P+C
    ablation paper default docs/results/base-270m-paper-zeroshot none,C
    $bin/ara eval ceiling --split paper --limit 200 ;;
  disjoint)
    # Trained on the disjoint split's own train side: its test pairs are held out.
    train training/configs/gemma3_270m_lora_cpu_disjoint.yaml "$disjoint_run"
    $bin/ara export --run "$disjoint_run" --quant f16 --lora-gguf
    ablation disjoint "lora:$disjoint_run/export/lora.gguf" \
      docs/results/finetuned-270m-disjoint none,C,F,F+P+C
    ablation disjoint default docs/results/base-270m-disjoint-zeroshot none,C
    $bin/ara eval ceiling --split disjoint --limit 200 ;;
  full)
    ablation paper finetuned docs/results/finetuned-270m-paper-full C 3000
    $bin/ara eval ceiling --split paper ;;
  *) echo "unknown step $step (train export ship eval disjoint full)" >&2; exit 2 ;;
  esac
done
