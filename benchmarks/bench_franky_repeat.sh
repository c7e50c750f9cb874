#!/usr/bin/env bash
# One more franky run of a Block Grasp checkpoint on igen-eval's trials 0..N-1 (the franky half of
# bench_rehearsal.sh, on the arm's clock): how far a franky rehearsal's count repeats
# (docs/benchmarks.md, "A longer training budget"). Run it with nothing else on the machine.
#
#   bash benchmarks/bench_franky_repeat.sh CHECKPOINT/pretrained_model OUT_DIR [TRIALS]
set -euo pipefail
cd "$(dirname "$0")/.."
checkpoint=${1:?usage: bench_franky_repeat.sh CHECKPOINT/pretrained_model OUT_DIR [TRIALS]}
out=${2:?usage: bench_franky_repeat.sh CHECKPOINT/pretrained_model OUT_DIR [TRIALS]}
trials=${3:-20}
host=${FRANKY_SIM_HOST:-127.0.0.2}
port=${FRANKY_SIM_SCENE_PORT:-7711}
mkdir -p "$out"
export MUJOCO_GL=${MUJOCO_GL:-egl}
tools/franky_sim/.venv/bin/python tools/franky_sim/serve.py --hostname "$host" --cube 0.5 0 --scene-port "$port" \
    > "$out/franky_sim.log" 2>&1 &
server=$!
trap 'kill $server 2>/dev/null || true' EXIT  # a franky-sim left running takes a core from what comes next
for _ in $(seq 60); do grep -q READY "$out/franky_sim.log" && break; sleep 1; done
grep -q READY "$out/franky_sim.log" || { echo "franky-sim did not start:"; cat "$out/franky_sim.log"; exit 1; }
.venv/bin/igen-deploy --policy.path="$checkpoint" --robot.type=franky --robot.host="$host" \
    --perception.type=franky_sim --perception.port="$port" --trials="$trials" --compare_sim=true --pace_on=arm \
    --output="$out/franky.json" > "$out/deploy.log" 2>&1
.venv/bin/python - "$out/franky.json" <<'PY'
import json, sys
report = json.load(open(sys.argv[1]))
trials = report["per_trial"]
failed = [i for i, t in enumerate(trials) if not t["success"]]
print(f"franky {len(trials) - len(failed)}/{len(trials)}, failed trials {failed}, hand orientation {report['hand_orientation']}")
PY
