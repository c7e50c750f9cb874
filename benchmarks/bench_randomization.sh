#!/usr/bin/env bash
# How each arm randomisation (--env.randomize.*, one at a time) changes generation on Block Grasp:
# MimicGen demonstrations (open-loop replay: sensitive to the arm's step response and latency) and
# IntervenGen with the scripted base policy (closed loop until its mistake, then an open-loop
# recovery). Sources: 10 demonstrations and 10 interventions recorded here without randomisation,
# as a user records them on one arm. Prints one line per (setting, mode): kept, attempted, rate.
#
#   MUJOCO_GL=egl bash benchmarks/bench_randomization.sh [output folder] [episodes]   # ~10 min on 2 cores
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
out=${1:-outputs/bench_randomization}
episodes=${2:-40}
bin=.venv/bin
mkdir -p "$out"
[ -e "$out/demos" ] || "$bin/igen-collect" --env.type=block_grasp --mode=demos --num_episodes=10 --seed=0 \
  --dataset.root="$out/demos" >/dev/null 2>&1
[ -e "$out/interventions" ] || "$bin/igen-collect" --env.type=block_grasp --mode=interventions --num_episodes=10 \
  --seed=1 --dataset.root="$out/interventions" >/dev/null 2>&1
source benchmarks/randomization_settings.sh
for name in "${RANDOMIZE_ORDER[@]:0:5}"; do  # none, then each flag alone
  for mode in mimicgen igen; do
    source=$([ "$mode" = mimicgen ] && echo demos || echo interventions)
    root="$out/${name}_${mode}"
    [ -e "$root" ] || "$bin/igen-generate" --env.type=block_grasp ${RANDOMIZE_SETTINGS[$name]} --mode="$mode" --seed=7 \
      --source.root="$out/$source" --num_episodes="$episodes" --max_attempts=$((episodes * 5)) --workers=2 \
      --dataset.root="$root" >/dev/null 2>&1
    "$bin/python" - "$root" "$name" "$mode" <<'PY'
import json, sys
root, name, mode = sys.argv[1:]
gen = json.load(open(f"{root}/meta/igen.json"))["generation"]
kept = json.load(open(f"{root}/meta/info.json"))["total_episodes"]
print(f"{name:>16} {mode:>9}: kept {kept} of {gen['attempted']} attempts ({gen['success_rate']:.1%})")
PY
  done
done
