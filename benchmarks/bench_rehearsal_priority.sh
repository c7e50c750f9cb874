#!/usr/bin/env bash
# The franky rehearsal path beside niced work, at a chosen niceness of its own: does a neighbour at nice 10
# (a table lane) disturb the 20 Hz loop and franky-sim's 1 kHz arm when they run at nice 0, as
# igen-table --rehearse runs them, and when they run at the lane's nice 10?
#
#   bash benchmarks/bench_rehearsal_priority.sh POLICY TRIALS OUT_DIR NICE
#
# POLICY: a checkpoint's pretrained_model/ or "scripted"; NICE: the niceness franky-sim and igen-deploy
# run at (0 needs root when this shell is niced). Prints successes, the loop's step and period times
# (p50/p95/max, ms) and the arm's clock against the wall's. Arrange the neighbours (or their absence) yourself.
set -euo pipefail
cd "$(dirname "$0")/.."
POLICY_ARG=${1:?usage: bench_rehearsal_priority.sh POLICY TRIALS OUT_DIR NICE}
TRIALS=${2:?trials}
OUT=${3:?out dir}
NICE=${4:?niceness}
HOST=${FRANKY_SIM_HOST:-127.0.0.2}
PORT=${FRANKY_SIM_SCENE_PORT:-7711}
POLICY=(--policy.path="$POLICY_ARG")
[ "$POLICY_ARG" = scripted ] && POLICY=()
mkdir -p "$OUT"
export MUJOCO_GL=${MUJOCO_GL:-egl}
BY=$((NICE - $(nice)))  # nice -n adds to the shell's own niceness

nice -n "$BY" tools/franky_sim/.venv/bin/python tools/franky_sim/serve.py --hostname "$HOST" --cube 0.5 0 \
  --scene-port "$PORT" > "$OUT/franky_sim.log" 2>&1 &
SERVER=$!
trap 'kill $SERVER 2>/dev/null || true' EXIT
for _ in $(seq 60); do grep -q READY "$OUT/franky_sim.log" && break; sleep 1; done
grep -q READY "$OUT/franky_sim.log" || { echo "franky-sim did not start:"; cat "$OUT/franky_sim.log"; exit 1; }

nice -n "$BY" .venv/bin/igen-deploy "${POLICY[@]}" --task=block_grasp --robot.type=franky --robot.host="$HOST" \
  --perception.type=franky_sim --perception.port="$PORT" --trials="$TRIALS" --output="$OUT/franky.json" \
  > "$OUT/deploy.log" 2>&1

.venv/bin/python - "$OUT/franky.json" "$NICE" <<'PY'
import json, sys
report = json.loads(open(sys.argv[1]).read())
loop, pace = report["loop"], report["pace"]
wins = sum(t["success"] for t in report["per_trial"])
cells = [f"nice {sys.argv[2]}", f"{wins}/{len(report['per_trial'])}"]
for part in ("step", "period"):
    stats = loop[part]
    cells.append(" / ".join(f"{stats.get(k, float('nan')):.1f}" for k in ("median_ms", "p95_ms", "max_ms")))
cells.append(f"{pace.get('arm_seconds_per_wall_second') or float('nan'):.3f}")
cells.append(str(len(report["deployment"]["faults"])))
print("| niceness | successes | loop step p50 / p95 / max [ms] | period p50 / p95 / max [ms] | arm s per wall s | faults |")
print("| " + " | ".join(cells) + " |")
PY
