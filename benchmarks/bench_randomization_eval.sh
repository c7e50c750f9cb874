#!/usr/bin/env bash
# A trained Block Grasp checkpoint on arms it was not trained on: igen-eval on the same trials with
# each --env.randomize.* flag alone (the ranges of bench_randomization.sh), then all together. It
# says how much a policy trained on one simulated arm depends on that arm's quirks.
#
#   MUJOCO_GL=egl bash benchmarks/bench_randomization_eval.sh CHECKPOINT/pretrained_model [TRIALS] [OUT_DIR] [SEED]
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
checkpoint=${1:?usage: bench_randomization_eval.sh CHECKPOINT/pretrained_model [TRIALS] [OUT_DIR] [SEED]}
trials=${2:-50}
out=${3:-outputs/bench_randomization_eval}
seed=${4:-2000003}  # igen-table's test trials (held out from every checkpoint choice)
mkdir -p "$out"
source benchmarks/randomization_settings.sh
for name in "${RANDOMIZE_ORDER[@]}"; do
  report="$out/$name.json"
  [ -e "$report" ] || .venv/bin/igen-eval --env.type=block_grasp ${RANDOMIZE_SETTINGS[$name]} --policy.path="$checkpoint" \
    --n_trials="$trials" --seed="$seed" --output="$report" >/dev/null 2>&1
  .venv/bin/python - "$report" "$name" <<'PY'
import json, sys
best = json.load(open(sys.argv[1]))["best"]
lo, hi = best["ci95"]
print(f"{sys.argv[2]:>16}: {best['successes']}/{best['trials']} ({100 * lo:.0f}-{100 * hi:.0f}%)")
PY
done
