#!/usr/bin/env bash
# Whether a candidate adapter may replace the shipped one (`--model finetuned`), measured
# side by side in one go on this machine:
#
#   scripts/judge_candidate.sh CANDIDATE.gguf JUDGE
#   scripts/judge_candidate.sh runs/recipe/gemma3-270m-nl2tl/export/lora.gguf handwritten12
#
# JUDGE is the blind suite written before the change and kept for it (in WAITING): both
# models answer it greedy and as `ara translate` does (repair 8), and `ara eval diff`
# lists what the candidate fixed and broke. Then every other held-out set (the suites
# not waiting, the compositional test, NL2TL's timed dev), greedy, for both; the help
# request, for both, and Experiment 2 with the candidate translating (15 min); and, unless PAPER=0, the paper split's lifted test side with repair (about an
# hour). Everything goes to runs/generalization/judge-C-S-V/ (C, S: the candidate's and
# the shipped file's sha256, 8 digits; V: the registered compositional version), so a
# rerun after an interruption goes on, and another candidate or data version gets its
# own folder. The shipped file's greedy answers on the other sets are copied from
# SHIPPED_ANSWERS (default docs/results/generalization/shipped-greedy) where they are
# its own on today's data. DRY_RUN=1 prints the commands instead. It ends with `ara eval verdict`,
# the shipping rule checked set by set into verdict.json, which `scripts/ship_adapter.py`
# reads; shipped or not, take JUDGE out of WAITING once it has answered.
set -euo pipefail
cd "$(dirname "$0")/.."
usage="usage: scripts/judge_candidate.sh CANDIDATE.gguf JUDGE"
candidate=${1:?$usage}
judge=${2:?$usage}
[ -f "$candidate" ] || { echo "error: no file $candidate" >&2; exit 2; }
py=.venv/bin/python
waiting=$($py -c "from ara.data.handwritten import WAITING; print(*WAITING)")
[[ " $waiting " == *" $judge "* ]] ||
  { echo "error: $judge is not a blind suite waiting for a change (WAITING: $waiting)" >&2
    exit 2; }
others=$($py -c "from ara.data.handwritten import SUITES, WAITING
print(*(s for s in SUITES if s not in WAITING and s != 'handwritten'))")
shipped=$($py -c "from ara.eval.translate.models import FINETUNED_LORA; print(FINETUNED_LORA)")
version=$($py -c "from ara.data import registered_version; print(registered_version('compositional'))")
root=judge-$(sha256sum "$candidate" | cut -c1-8)-$(sha256sum "$shipped" | cut -c1-8)-$version
model=lora:$candidate

step() { echo "== $(date -u +%H:%M) $*"; }
run() {  # a command, or what it would be
  if [ -n "${DRY_RUN:-}" ]; then echo "would run: $*"; else "$@"; fi
}
eval_sets() {  # VARIANTS REPAIR MODEL NAME SET...
  run env VARIANTS="$1" REPAIR="$2" scripts/eval_generalization.sh "$3" "$root/$4" "${@:5}"
}
step "$root: the judge, $judge: greedy, then repair 8, candidate and shipped"
eval_sets C 0 "$model" candidate-greedy "$judge"
eval_sets C 0 finetuned shipped-greedy "$judge"
eval_sets C 8 "$model" candidate-repair8 "$judge"
eval_sets C 8 finetuned shipped-repair8 "$judge"
for kind in greedy repair8; do
  for form in lifted grounded; do
    step "$judge-$form, $kind: shipped -> candidate"
    run .venv/bin/ara eval diff "runs/generalization/$root/shipped-$kind/$judge-$form" \
      "runs/generalization/$root/candidate-$kind/$judge-$form" --show 0
  done
done
step "the other held-out sets, greedy: $others compositional timed"
eval_sets C 0 "$model" candidate-greedy $others compositional timed
# The shipped file's greedy answers are committed with it (SHIPPED_ANSWERS): a set whose
# runs there are this very file's, on the data version registered now and with the
# judge's settings, is copied rather than asked again (half an hour on 2 cores).
asked=$($py - "$shipped" "${SHIPPED_ANSWERS:-docs/results/generalization/shipped-greedy}" \
  "runs/generalization/$root/shipped-greedy" "${DRY_RUN:-}" $others compositional timed <<'PY'
import json, shutil, sys
from pathlib import Path
from ara.data import registered_version
from ara.eval.translate.backends.llama_cpp_backend import lora_id
from ara.eval.verdict import HELD_OUT_LIMITS, SUITE_LIMIT
shipped, saved, out, dry, *sets = sys.argv[1:]
lora = lora_id(shipped)
asked = []
for split in sets:
    forms = ("lifted",) if split == "timed" else ("lifted", "grounded")
    runs = [Path(saved) / f"{split}-{form}" for form in forms]
    metas = [json.loads((r / "run.json").read_text()) for r in runs
             if (r / "run.json").is_file() and (r / "samples.jsonl").is_file()]
    if len(metas) < len(forms) or not all(
            m["model_id"].endswith(lora) and m["data"]["version"] == registered_version(split)
            and m["config"]["variants"] == ["C"] and not m["config"].get("repair")
            and m["config"]["shots"] == [5]
            and m["config"]["limit"] == HELD_OUT_LIMITS.get(split, SUITE_LIMIT)
            for m in metas):
        asked.append(split)
        continue
    for run, meta in zip(runs, metas):
        copy = Path(out) / run.name
        print(f"{'would copy' if dry else 'copied'} {run} to {copy}", file=sys.stderr)
        if dry or copy.exists():
            continue
        shutil.copytree(run, copy)
        meta["config"]["model"] = "finetuned"  # what a rerun here would ask for: it resumes
        (copy / "run.json").write_text(json.dumps(meta, indent=2, sort_keys=True) + "\n")
print(*asked)
PY
)
[ -z "$asked" ] || eval_sets C 0 finetuned shipped-greedy $asked
run $py scripts/generalization_table.py --results "runs/generalization/$root" \
  --models shipped-greedy,candidate-greedy
step "the help request, candidate and shipped"
run mkdir -p "runs/generalization/$root"
help_of() {  # MODEL FILE: skipped where an earlier, interrupted judge wrote it
  [ -f "runs/generalization/$root/$2" ] ||
    run $py bench/help_request_wordings.py --model "$1" --out "runs/generalization/$root/$2"
}
help_of "$model" help-request-wordings.json
help_of finetuned help-request-wordings-shipped.json
step "Experiment 2, the candidate translating every request (its auctions against the template's)"
run .venv/bin/ara coord exp2 --out "runs/generalization/$root/exp2-candidate" --planner milp \
  --model "$model" --wordings all
if [ "${PAPER:-1}" != 0 ]; then
  step "the paper split, lifted test side, repair 8"
  run .venv/bin/ara eval ablation --split paper --form lifted --limit 3000 --model "$model" \
    --variants C --shots 5 --reruns 1 --seed 0 --spot-timeout 10 --resume --repair 8 \
    --repair-by samples+edits --doubt 0.5 --no-progress \
    --out "runs/generalization/$root/paper-repair8"
fi
step "the verdict (the shipping rule: ara eval verdict --help)"
run .venv/bin/ara eval verdict "runs/generalization/$root" --judge "$judge"
step "done: runs/generalization/$root"
