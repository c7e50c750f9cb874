#!/usr/bin/env bash
# A Block Grasp checkpoint in igen-eval on the rehearsal's 20 trials, on the training arm and on
# three changed arms it was not evaluated on: softer (stiffness x0.7), later (40 ms) and slower in
# z only (z stiffness x0.6). The successes on the changed arms say how much the policy depends on
# the arm it trained on (docs/benchmarks.md, "Is it the arm?").
#
#   MUJOCO_GL=egl bash benchmarks/bench_arm_probes.sh CHECKPOINT/pretrained_model OUT_DIR
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
checkpoint=${1:?usage: bench_arm_probes.sh CHECKPOINT OUT_DIR}
out=${2:?usage: bench_arm_probes.sh CHECKPOINT OUT_DIR}
mkdir -p "$out"
trials=(--env.type=block_grasp --policy.path="$checkpoint" --n_trials=20 --seed=1000003)
run() {  # name, command...: skipped once its report exists
  local name=$1; shift
  [ -e "$out/$name.json" ] || "$@" --output="$out/$name.json" > "$out/$name.log" 2>&1
}
run training .venv/bin/igen-eval "${trials[@]}"
run kp0.7 .venv/bin/igen-eval "${trials[@]}" --env.randomize.kp_scale='[0.7,0.7]'
run latency40ms .venv/bin/igen-eval "${trials[@]}" --env.randomize.latency='[0.04,0.04]'
run z_kp0.6 .venv/bin/python benchmarks/bench_arm_probe.py --kp_axes 1,1,0.6 -- "${trials[@]}"
.venv/bin/python - "$out" <<'PY'
import json, sys
from pathlib import Path
total = 0
for name in ("training", "kp0.7", "latency40ms", "z_kp0.6"):
    result = json.loads((Path(sys.argv[1]) / f"{name}.json").read_text())["results"][0]
    failed = [i for i, ok in enumerate(result["per_trial"]) if not ok]
    total += result["successes"] if name != "training" else 0
    print(f"{name:12s} {result['successes']:2d}/20  failed {failed}")
print(f"changed arms {total}/60")
PY
