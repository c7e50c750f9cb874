#!/usr/bin/env bash
# Every task's simulation and generation speed, measured in one run so the tasks compare fairly:
# per-core control steps/s against the raw physics limit (bench_env.py), then per task the
# generator with 1 and 2 workers, every mode with 2 workers, and the full igen-generate command
# for 1000 kept IntervenGen episodes (bench_generation.py). Sources: 10 demonstrations and 10
# human-gated interventions per task, recorded here by the scripted operator.
#
#   MUJOCO_GL=egl bash benchmarks/bench_tasks.sh [output folder]      # ~30 min on 2 cores; idle machine
#   IGEN_BENCH_TASKS="coffee" MUJOCO_GL=egl bash benchmarks/bench_tasks.sh   # only the tasks named
#   IGEN_BENCH_EPISODES=30 IGEN_BENCH_BIG=0 IGEN_BENCH_REPEATS=1 ...   # smaller runs (defaults 150, 1000, 3)
#
# Nut-and-Peg's interventions are recorded on geometry 2 (the handle always on the other side), so
# every source has a takeover; its generation runs on the default mixture, as its table does.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
out=${1:-outputs/bench_tasks}
tasks=(${IGEN_BENCH_TASKS:-block_grasp nut_insertion two_piece_assembly coffee nut_and_peg})
bin=.venv/bin
episodes=${IGEN_BENCH_EPISODES:-150}
big=${IGEN_BENCH_BIG:-1000}
repeats=${IGEN_BENCH_REPEATS:-3}
intervention_flags() { [ "$1" = nut_and_peg ] && echo "--env.geometry=2" || true; }
mkdir -p "$out"
for task in "${tasks[@]}"; do
  [ -e "$out/${task}_demos" ] || "$bin/igen-collect" --env.type="$task" --mode=demos --num_episodes=10 --seed=0 \
    --dataset.root="$out/${task}_demos" >/dev/null 2>&1
  [ -e "$out/${task}_interventions" ] || "$bin/igen-collect" --env.type="$task" $(intervention_flags "$task") \
    --mode=interventions --num_episodes=10 --seed=1 --dataset.root="$out/${task}_interventions" >/dev/null 2>&1
done
"$bin/python" benchmarks/bench_env.py --tasks "${tasks[@]}" | tee "$out/env.json"
for task in "${tasks[@]}"; do
  "$bin/python" benchmarks/bench_generation.py --task="$task" --sources="$out/${task}_interventions" \
    --demos="$out/${task}_demos" --episodes="$episodes" --big="$big" --repeats="$repeats" | tee "$out/generation_${task}.json"
done
