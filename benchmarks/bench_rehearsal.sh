#!/usr/bin/env bash
# A trained Block Grasp checkpoint through both rehearsal paths on igen-eval's trials 0..N-1
# (docs/benchmarks.md, "The trained policy through the franky driver stack"):
#   1. the MuJoCo arm backend (the training simulator) with the simulator's cube pose;
#   2. the franky backend against franky-sim (another simulator, behind libfranka's protocol),
#      the cube placed per trial over franky-sim's scene channel.
# Both run --compare_sim=true: igen-eval's own rollout of the same checkpoint on the same trials.
#
#   bash benchmarks/bench_rehearsal.sh outputs/bg_igen/train/igen/checkpoints/last/pretrained_model 20 outputs/rehearsal
# FRANKY_CONTROLLER=trajectory|impedance picks the franky backend's controller (default: the backend's own).
# Further arguments go to the franky igen-deploy run, e.g. --robot.tracker_stiffness=3000.
# HAND_ORIENTATION=goal|measured sets igen-deploy --hand_orientation on both paths (default: igen-deploy's).
set -euo pipefail
cd "$(dirname "$0")/.."
CHECKPOINT=${1:?usage: bench_rehearsal.sh CHECKPOINT/pretrained_model|scripted [TRIALS] [OUT_DIR] [igen-deploy args]}
TRIALS=${2:-20}
OUT=${3:-outputs/rehearsal}
EXTRA=("${@:4}")
HOST=${FRANKY_SIM_HOST:-127.0.0.2}
PORT=${FRANKY_SIM_SCENE_PORT:-7711}
CONTROLLER=()
[ -n "${FRANKY_CONTROLLER:-}" ] && CONTROLLER=(--robot.controller="$FRANKY_CONTROLLER")
POLICY=(--policy.path="$CHECKPOINT")
[ -n "${HAND_ORIENTATION:-}" ] && POLICY+=(--hand_orientation="$HAND_ORIENTATION")
[ "$CHECKPOINT" = scripted ] && POLICY=("${POLICY[@]:1}")  # the task's scripted policy (acts on what it believes)
mkdir -p "$OUT"
export MUJOCO_GL=${MUJOCO_GL:-egl}

.venv/bin/igen-deploy "${POLICY[@]}" --robot.type=sim --perception.type=truth \
    --trials="$TRIALS" --compare_sim=true --output="$OUT/mujoco.json"

tools/franky_sim/.venv/bin/python tools/franky_sim/serve.py --hostname "$HOST" --cube 0.5 0 --scene-port "$PORT" \
    > "$OUT/franky_sim.log" 2>&1 &
SERVER=$!
trap 'kill $SERVER 2>/dev/null || true' EXIT
for _ in $(seq 60); do grep -q READY "$OUT/franky_sim.log" && break; sleep 1; done
grep -q READY "$OUT/franky_sim.log" || { echo "franky-sim did not start:"; cat "$OUT/franky_sim.log"; exit 1; }

.venv/bin/igen-deploy "${POLICY[@]}" --robot.type=franky --robot.host="$HOST" "${CONTROLLER[@]}" \
    --perception.type=franky_sim --perception.port="$PORT" \
    --trials="$TRIALS" --compare_sim=true --output="$OUT/franky.json" "${EXTRA[@]}"

.venv/bin/python benchmarks/rehearsal_summary.py "$OUT/mujoco.json" "$OUT/franky.json"
