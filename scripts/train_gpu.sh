#!/usr/bin/env bash
# Fine-tune on a GPU box: one GPU, or all of them through accelerate (no code change;
# a staged recipe, one GPU).
#
#   scripts/train_gpu.sh CONFIG.yaml [--max-steps N] [--resume]
#
# Needs `make setup` (or `pip install -e .[all]`) in the box's environment, and the base
# model folder named in the config.
set -euo pipefail
config=${1:?usage: scripts/train_gpu.sh CONFIG.yaml [--max-steps N] [--resume]}
shift
gpus=$(python -c "import torch; print(torch.cuda.device_count())")
# A staged recipe (a config with `stages:`) runs in one process, on the first GPU.
if grep -q '^stages:' "$config"; then
    gpus=1
fi
if [ "$gpus" -gt 1 ]; then
    exec accelerate launch --num_processes "$gpus" -m ara.cli train --config "$config" "$@"
fi
exec ara train --config "$config" "$@"
