#!/usr/bin/env bash
# Whether a candidate adapter may replace the shipped one (`--model finetuned`), measured
# side by side in one go on this machine:
#
#   scripts/judge_candidate.sh CANDIDATE.gguf JUDGE [NAME]
#   scripts/judge_candidate.sh runs/recipe/gemma3-270m-nl2tl/export/lora.gguf handwritten7
#
# JUDGE is the blind suite written before the change and kept for it (in WAITING): both
# models answer it greedy and as `ara translate` does (repair 8), and `ara eval diff`
# lists what the candidate fixed and broke. Then every other held-out set (the suites
# not waiting, the compositional test, NL2TL's timed dev), greedy, for both; the help
# request; and, unless PAPER=0, the paper split's lifted test side with repair (about an
# hour). Results: runs/generalization/{NAME,shipped}-{greedy,repair8}/,
# runs/bench/help-request-wordings-NAME.json, runs/NAME-paper/; each step resumes, so a
# rerun after an interruption goes on. Ship only if the candidate is at least as good on
# the blind sets (`scripts/ship_adapter.py`), then take JUDGE out of WAITING.
set -euo pipefail
cd "$(dirname "$0")/.."
usage="usage: scripts/judge_candidate.sh CANDIDATE.gguf JUDGE [NAME]"
candidate=${1:?$usage}
judge=${2:?$usage}
name=${3:-candidate}
[ -f "$candidate" ] || { echo "error: no file $candidate" >&2; exit 2; }
.venv/bin/python -c "from ara.data.handwritten import WAITING; import sys
sys.exit(0 if sys.argv[1] in WAITING else 1)" "$judge" ||
  { echo "error: $judge is not a blind suite waiting for a change (WAITING)" >&2; exit 2; }
model=lora:$candidate
others=$(.venv/bin/python -c "from ara.data.handwritten import SUITES, WAITING
print(*(s for s in SUITES if s not in WAITING and s != 'handwritten'))")

step() { echo "== $(date -u +%H:%M) $*"; }
step "the judge, $judge: greedy, then repair 8, candidate and shipped"
VARIANTS=C scripts/eval_generalization.sh "$model" "$name-greedy" "$judge"
VARIANTS=C scripts/eval_generalization.sh finetuned shipped-greedy "$judge"
VARIANTS=C REPAIR=8 scripts/eval_generalization.sh "$model" "$name-repair8" "$judge"
VARIANTS=C REPAIR=8 scripts/eval_generalization.sh finetuned shipped-repair8 "$judge"
for kind in greedy repair8; do
  for form in lifted grounded; do
    step "$judge-$form, $kind: shipped -> $name"
    .venv/bin/ara eval diff "runs/generalization/shipped-$kind/$judge-$form" \
      "runs/generalization/$name-$kind/$judge-$form" --show 0
  done
done
step "the other held-out sets, greedy: $others compositional timed"
VARIANTS=C scripts/eval_generalization.sh "$model" "$name-greedy" $others compositional timed
VARIANTS=C scripts/eval_generalization.sh finetuned shipped-greedy $others compositional timed
.venv/bin/python scripts/generalization_table.py --models "shipped-greedy,$name-greedy"
step "the help request"
mkdir -p runs/bench
.venv/bin/python bench/help_request_wordings.py --model "$model" \
  --out "runs/bench/help-request-wordings-$name.json"
if [ "${PAPER:-1}" != 0 ]; then
  step "the paper split, lifted test side, repair 8"
  .venv/bin/ara eval ablation --split paper --form lifted --limit 3000 --model "$model" \
    --variants C --shots 5 --reruns 1 --seed 0 --spot-timeout 10 --resume --repair 8 \
    --repair-by samples+edits --doubt 0.5 --no-progress --out "runs/$name-paper" > /dev/null
  .venv/bin/ara eval score "runs/$name-paper" | head -20
fi
step "done"
