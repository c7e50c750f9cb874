#!/usr/bin/env bash
# Does lerobot-train survive being paused (SIGSTOP) and resumed (SIGCONT), as the table lanes pause
# each other while franky-sim runs? A 1500-step BC-RNN training (the 2-Piece table's base command, its
# own output directory) is stopped STOP_S seconds of every STOP_S + RUN_S until it ends; prints each
# stop and continue, then the exit code (134: SIGABRT, 139: SIGSEGV) and the number of cycles.
#   bash benchmarks/bench_training_pauses.sh OUT_DIR [DATASET_ROOT]
# env: STOP_S (20), RUN_S (20), STEPS (1500). The training runs at nice 10 with a Python fault handler.
set -uo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
out=${1:?usage: bench_training_pauses.sh OUT_DIR [DATASET_ROOT]}
data=${2:-outputs/tables/two_piece_assembly/data/base}
mkdir -p "$out" && rm -rf "$out/train"
setsid nice -n 10 env OMP_NUM_THREADS=1 PYTHONFAULTHANDLER=1 .venv/bin/lerobot-train --policy.type=bc_rnn \
  --policy.device=cpu --policy.push_to_hub=false --dataset.repo_id=local/base --dataset.root="$data" \
  --output_dir="$out/train" --steps="${STEPS:-1500}" --batch_size=100 --num_workers=2 --save_freq=100000 \
  --seed=1001 --wandb.enable=false > "$out/train.log" 2>&1 &
pid=$!  # setsid made it the leader of its own process group: -$pid pauses its loader workers too
stamp() { date +%T.%N | cut -c1-12; }
cycles=0
sleep 40
while kill -0 "$pid" 2>/dev/null; do
  kill -STOP -- "-$pid" && echo "$(stamp) stop"
  sleep "${STOP_S:-20}"
  kill -CONT -- "-$pid" && echo "$(stamp) cont"
  cycles=$((cycles + 1))
  sleep "${RUN_S:-20}"
done
wait "$pid"
rc=$?
echo "$(stamp) ended: exit $rc after $cycles stop/continue cycles"
