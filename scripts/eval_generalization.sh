#!/usr/bin/env bash
# Translation accuracy on sentences a model never trained on, next to the paper split.
#
#   scripts/eval_generalization.sh MODEL NAME [SET ...]
#
# MODEL is an `ara --model` value (finetuned, finetuned-paper, default, lora:FILE.gguf);
# NAME names the results folder runs/generalization/NAME/<set>-<form>/. SETs
# (default: all): each hand-written suite of ara.data.handwritten.SUITES but the blind
# ones in WAITING (all of its entries; docs/data.md says which were read to guide what),
# compositional (held-out shapes and phrasings, 50 lifted + 50 grounded), timed (NL2TL's lifted dev file, 100),
# paper and disjoint (100 lifted each; ara.eval.verdict.HELD_OUT_LIMITS holds these sizes);
# $LIMIT overrides those sampled sizes (a suite
# always runs whole). Variants: $VARIANTS (default none,C,F+C; C,F+C on paper and
# disjoint, where a fine-tune's none equals C), 5 shots for F, one rerun, seed 0,
# Spot's limit 5 s a pair (undecided counts as wrong); $REPAIR (default 0) turns repair on
# when a constrained answer leaves part of the request out (`ara eval ablation --repair`,
# $REPAIR answers drawn where sampling is the way), by $REPAIR_BY (default samples+edits),
# also acting on a complete answer the model gives a probability below $DOUBT (default
# 0.5; 0: gaps only).
# $SHOTS (default 5) are the F variants' worked examples, chosen by $EXAMPLES_BY (default
# random; similar: each test pair's most similar pairs of the pool, never its own sentence).
# The set timed-unseen is NL2TL's timed dev pairs whose sentence no training pair says
# (written to runs/data/timed-unseen.jsonl and read with --data).
# Each run resumes from its samples.
# `scripts/generalization_table.py` prints the table from what is there.
set -euo pipefail
cd "$(dirname "$0")/.."
model=${1:?usage: eval_generalization.sh MODEL NAME [SET ...]}
name=${2:?usage: eval_generalization.sh MODEL NAME [SET ...]}
shift 2
# Blind suites still waiting for the change they judge (WAITING) run only when named.
all_suites=$(.venv/bin/python -c "from ara.data.handwritten import SUITES; print(*SUITES)")
suites=$(.venv/bin/python -c "from ara.data.handwritten import SUITES, WAITING
print(*(s for s in SUITES if s not in WAITING))")
sets=${*:-$suites compositional timed paper disjoint}
variants=${VARIANTS:-none,C,F+C}
out=runs/generalization/$name
limit_of() {  # SET: $LIMIT, else the size ara.eval.verdict.HELD_OUT_LIMITS gives it
  echo "${LIMIT:-$(.venv/bin/python -c "import sys; from ara.eval.verdict import HELD_OUT_LIMITS as L, SUITE_LIMIT
print(L.get(sys.argv[1], SUITE_LIMIT))" "$1")}"
}

run() {  # SPLIT FORM LIMIT [VARIANTS]
  .venv/bin/ara eval ablation --split "$1" --form "$2" --limit "$3" --model "$model" \
    --variants "${4:-$variants}" --shots "${SHOTS:-5}" --examples-by "${EXAMPLES_BY:-random}" \
    --reruns 1 --seed 0 --spot-timeout 5 --resume \
    --repair "${REPAIR:-0}" --repair-by "${REPAIR_BY:-samples+edits}" --doubt "${DOUBT:-0.5}" \
    --no-progress --out "$out/$1-$2" > /dev/null
  echo "done: $name $1 $2"
}

for set in $sets; do
  case $set in
  handwritten*)
    [[ " $all_suites " == *" $set "* ]] || { echo "unknown suite $set ($all_suites)" >&2; exit 2; }
    [[ " $suites " == *" $set "* ]] ||
      echo "note: $set is a blind suite waiting for a change to judge (WAITING); its answers spend it" >&2
    suite_limit=$(LIMIT='' limit_of "$set")  # a suite runs whole, whatever $LIMIT says
    run "$set" lifted "$suite_limit"; run "$set" grounded "$suite_limit" ;;
  compositional) run compositional lifted "$(limit_of compositional)"
    run compositional grounded "$(limit_of compositional)" ;;
  timed) run timed lifted "$(limit_of timed)" ;;
  timed-unseen)
    mkdir -p runs/data
    .venv/bin/python - <<'PY'
import json
from ara.data import load_or_prepare
from ara.data.mixture import sentence_key
seen = {sentence_key(r.nl) for r in load_or_prepare("compositional").records("train")}
with open("runs/data/timed-unseen.jsonl", "w") as f:
    for r in load_or_prepare("timed").records("test"):
        if sentence_key(r.nl) not in seen:
            f.write(json.dumps({"nl": r.nl, "aps": list(r.aps), "stl": r.stl}) + "\n")
PY
    .venv/bin/ara eval ablation --data runs/data/timed-unseen.jsonl --limit "$(limit_of timed-unseen)" \
      --model "$model" --variants "$variants" --shots "${SHOTS:-5}" \
      --examples-by "${EXAMPLES_BY:-random}" --reruns 1 --seed 0 --spot-timeout 5 --resume \
      --repair "${REPAIR:-0}" --repair-by "${REPAIR_BY:-samples+edits}" --doubt "${DOUBT:-0.5}" \
      --no-progress --out "$out/timed-unseen-lifted" > /dev/null
    echo "done: $name timed-unseen" ;;
  paper|disjoint) run "$set" lifted "$(limit_of "$set")" "${VARIANTS:-C,F+C}" ;;
  *) echo "unknown set $set ($suites compositional timed timed-unseen paper disjoint)" >&2
     exit 2 ;;
  esac
done
