#!/usr/bin/env bash
# The shipped fine-tune, end to end, on a CPU: two training runs of 85 and 50 min on 2
# cores (v3 and v4, each fits one session), a 65-min run from v4's adapter on the
# mixture of generator 3.3.0 (v13), a 75-min run from v13's adapter on generator 3.4.0's
# (v14), a 70-min run from their mean on generator 3.5.0's (v15), the mean of that mean
# and v15 reduced to rank 16 (a "soup", seconds), a 45-min run from it (v16, shipped),
# then export, ship and the evaluations (about 45 min).
#
#   scripts/finetune_270m.sh [STEP ...]   steps: train continue v6 v7 v8 v9 v10 v11 v12 v13
#                                         v14 v15 v16 v17 v18 v19 v20 soup soup17 export
#                                         ship eval paper disjoint full
#                                         (default: train continue v13 v14 v15 soup v16 v17
#                                         soup17 export ship eval)
#
# train: v3 (training/configs/gemma3_270m_lora_cpu_compositional.yaml); continue: v4,
#   400 more steps from v3's adapter (..._compositional_v4.yaml); v6, v7, v8: three more
#   runs from v4's adapter (v6 on mixture 820c2d11c0c8; v7 300 steps and v8, from v6's
#   adapter, 150 steps, both on 6c3132045205); v10: v7's config with NL2TL's timed rows
#   counted twice (v6 to v10 made the soup shipped until 2026-11-24, v7 + v8 + v10, and
#   are not in the default steps; v9 is v7 with another seed); v11, v12: v10's recipe on
#   mixture 690d5d4a1e5f, seeds 4 and 6 (their soup was shipped until 2026-11-24);
#   v13: v11's recipe on 9c33668eac7c (generator 3.3.0); v14: 300 steps from v13's
#   adapter on aaa2649e1656 (3.4.0), seed 6, navi's rows x2; v15: 300 steps from the
#   mean of v13 and v14 (committed as docs/results/training/compositional-270m-soup-v13v14,
#   made by `ara soup --run ..-v13 --run ..-v14`; shipped until 2026-11-24) on
#   89be643cc979 (3.5.0), seed 8; soup: the mean of that mean and v15, reduced to rank
#   16 by SVD (`ara soup --rank 16`, from the adapters committed under
#   docs/results/training/; shipped at rank 64 until 2026-11-24; committed as
#   compositional-270m-soup-v13v14v15-r16); v16: 300 steps from that soup on
#   89be643cc979, seed 9, the help requests counted twice; v17: 300 more from v16, seed
#   10; soup17: the mean of v16 and v17 at rank 16; export/ship: it becomes `--model
#   finetuned`. v18 to v20 (on 3.6.0's e910409c3f2c, from v16 and from the shipped soup)
#   were not shipped and are not in the default steps. A mixture that is no longer
#   registered (v6 to v13's) is prepared with the release that registered it
#   (`git log -p data/versions.json`).
# eval: the generalization runs of the new adapter, the paper-split adapter and the base
#   model (scripts/eval_generalization.sh), the round trip, the help-request wordings.
# paper: retrains the paper-split adapter (`--model finetuned-paper`, Table I) from its
#   config and ships it; disjoint: an adapter trained on the disjoint split's train side;
#   full: the shipped adapter zero-shot under the grammar on the whole paper test side.
#
# Each step can be rerun alone; training resumes from its newest checkpoint and the
# evaluations from their finished samples. The v5 to v8 configs start from the adapters
# committed under docs/results/training/ (v4 and v6), so v6 to v8 can run without the
# earlier runs' folders, as v15 and v16 can.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=.venv/bin
first_run=runs/train/gemma3-270m-lora-compositional
v4_run=runs/train/gemma3-270m-lora-compositional-v4
soup_run=runs/train/gemma3-270m-lora-compositional-soup
run=runs/train/gemma3-270m-lora-compositional-soup-v16v17
paper_run=runs/train/gemma3-270m-lora
disjoint_run=runs/train/gemma3-270m-lora-disjoint
steps=${*:-train continue v13 v14 v15 soup v16 v17 soup17 export ship eval}

train() {  # CONFIG RUN_FOLDER
  if [ -f "$2/run.json" ]; then resume=--resume; else resume=; fi
  $bin/ara train --config "$1" $resume
}

ablation() {  # SPLIT MODEL OUT VARIANTS [LIMIT]
  $bin/ara eval ablation --split "$1" --model "$2" --out "$3" --variants "$4" \
    --shots 5 --reruns 1 --limit "${5:-200}" --resume --no-progress
}

ship() {  # RUN_FOLDER FILE_NAME PARITY_SPLIT
  cp "$1/export/lora.gguf" "eval/models/$2"
  $bin/python - "$1" "$2" "$3" <<'PY'
import json, sys
from pathlib import Path
from ara.data import load_or_prepare
from ara.eval.models import SHIPPED
from ara.eval.llama_check import default_model_path
from ara.provenance import sha256_file
from ara.training.export import parity
run, name, split = Path(sys.argv[1]), sys.argv[2], sys.argv[3]
adapter = SHIPPED / name
manifest = {"file": name, "sha256": sha256_file(adapter),
            "run": json.loads((run / "run.json").read_text()),
            "export": json.loads((run / "export" / "export.json").read_text()),
            # A soup was never trained as a whole: no held-out check of its own
            "heldout": (json.loads((run / "heldout.json").read_text())
                        if (run / "heldout.json").is_file() else None)}
# What a user runs: the adapter on the embedded Q4_K_M base, against the merged HF model
data = load_or_prepare(split, 0)
records = data.records("test", "lifted")[:20] + data.records("test", "grounded")[:20]
manifest["shipped_parity"] = {
    "what": "embedded Q4_K_M GGUF + this adapter (llama.cpp) vs the merged HF model "
            f"(transformers, fp32), greedy, zero-shot, unconstrained; 20 lifted + 20 "
            f"grounded {split} test pairs",
    **parity(Path(default_model_path()), run / "export" / "merged-hf", records, lora=adapter)}
adapter.with_suffix(".json").write_text(json.dumps(manifest, indent=2) + "\n")
PY
}

for step in $steps; do
  case $step in
  train)
    train training/configs/gemma3_270m_lora_cpu_compositional.yaml "$first_run" ;;
  continue)
    train training/configs/gemma3_270m_lora_cpu_compositional_v4.yaml "$v4_run" ;;
  v6|v7|v8|v9|v10|v11|v12|v13|v14|v15|v16|v17|v18|v19|v20)
    train "training/configs/gemma3_270m_lora_cpu_compositional_$step.yaml" \
      "runs/train/gemma3-270m-lora-compositional-$step" ;;
  soup)
    # The committed records of the parts; a rerun's parts are in runs/train/..-vN
    parts=docs/results/training/compositional-270m
    $bin/ara soup --run $parts-soup-v13v14 --run $parts-v15 --rank 16 --out "$soup_run" ;;
  soup17)
    # v16 and v17 (v16 trained on, seed 10), their mean at rank 16: shipped
    parts=docs/results/training/compositional-270m
    $bin/ara soup --run $parts-v16 --run $parts-v17 --rank 16 --out "$run" ;;
  export)
    # f16 GGUF of the merged model + the adapter alone as a GGUF LoRA; parity on 20 pairs
    $bin/ara export --run "$run" --quant f16 --lora-gguf --parity 20 ;;
  ship)
    ship "$run" gemma3-270m-nl2tl-lora.gguf compositional ;;
  eval)
    scripts/eval_generalization.sh finetuned compositional-adapter-270m
    VARIANTS=C,F+C scripts/eval_generalization.sh finetuned-paper paper-adapter-270m \
      handwritten handwritten2 compositional timed
    VARIANTS=C,F+C scripts/eval_generalization.sh default base-270m \
      handwritten handwritten2 compositional timed
    $bin/python scripts/generalization_table.py
    $bin/python scripts/round_trip.py
    $bin/python bench/help_request_wordings.py ;;
  paper)
    train training/configs/gemma3_270m_lora_cpu.yaml "$paper_run"
    $bin/ara export --run "$paper_run" --quant f16 --lora-gguf --parity 20
    ship "$paper_run" gemma3-270m-nl2tl-paper-lora.gguf paper ;;
  disjoint)
    # Trained on the disjoint split's own train side: its test pairs are held out.
    train training/configs/gemma3_270m_lora_cpu_disjoint.yaml "$disjoint_run"
    $bin/ara export --run "$disjoint_run" --quant f16 --lora-gguf
    ablation disjoint "lora:$disjoint_run/export/lora.gguf" \
      docs/results/finetuned-270m-disjoint none,C,F,F+P+C
    ablation disjoint default docs/results/base-270m-disjoint-zeroshot none,C
    $bin/ara eval ceiling --split disjoint --limit 200 ;;
  full)
    ablation paper finetuned docs/results/compositional-adapter-270m-paper-full C 3000
    $bin/ara eval ceiling --split paper ;;
  *) echo "unknown step $step (train continue v6 v7 v8 v9 v10 v11 v12 v13 v14 v15 v16 v17 v18 v19" \
       "v20 soup soup17" \
       "export ship eval paper disjoint full)" >&2
     exit 2 ;;
  esac
done
