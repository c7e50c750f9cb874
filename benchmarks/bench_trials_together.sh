#!/usr/bin/env bash
# igen-eval of one training run's checkpoints with its trials one at a time (--trials_together=1) and
# grouped (the default, 10 per batched BC-RNN call), as a table's validation step runs them (2 workers):
# wall time of each, and a check that every trial's outcome and step count are the same both ways.
#   bash benchmarks/bench_trials_together.sh [train_dir=outputs/tables/nut_insertion/train/base/seed1000] [task=nut_insertion]
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
run=${1:-outputs/tables/nut_insertion/train/base/seed1000}
task=${2:-nut_insertion}
out=outputs/trials_together
mkdir -p "$out"
export MUJOCO_GL=egl HF_HUB_OFFLINE=1
for together in 1 10; do
  start=$(date +%s.%N)
  .venv/bin/igen-eval --env.type="$task" --train_dir="$run" --every=2 --n_trials=50 --seed=2000003 --workers=2 \
    --trials_together="$together" --output="$out/together$together.json" > "$out/together$together.log" 2>&1
  echo "trials_together=$together: $(echo "$(date +%s.%N) - $start" | bc) s wall"
  grep -E "^step" "$out/together$together.log" | sed "s/^/  /"
done
.venv/bin/python - "$out" <<'PY'
import json, sys
a, b = (json.load(open(f"{sys.argv[1]}/together{k}.json"))["results"] for k in (1, 10))
same = all(x["per_trial"] == y["per_trial"] and x["per_trial_steps"] == y["per_trial_steps"] for x, y in zip(a, b, strict=True))
print(f"{sum(x['trials'] for x in a)} trials over {len(a)} checkpoints: outcomes and step counts {'identical' if same else 'DIFFER'}")
sys.exit(0 if same else 1)
PY
