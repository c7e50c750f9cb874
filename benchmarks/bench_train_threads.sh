#!/usr/bin/env bash
# Would two trainings at one thread each beat one at two threads on this 2-core machine?
# (docs/benchmarks.md, "What a table costs"). Three BC-RNN runs of STEPS steps on one dataset, each
# measured from lerobot-train's own progress bar (steps/s over its last stretch):
#   1. one training, torch's default threads (the tables' setting);
#   2. one training, OMP_NUM_THREADS=1;
#   3. two trainings at once, OMP_NUM_THREADS=1 each (different seeds).
# Run it on an idle machine:
#   bash benchmarks/bench_train_threads.sh outputs/nut_repro/data/train_igen [STEPS] [OUT]
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
data=${1:?usage: bench_train_threads.sh DATASET_ROOT [STEPS] [OUT]}
steps=${2:-400}
out=${3:-outputs/bench_train_threads}
mkdir -p "$out" && rm -rf "$out"/{default,one_thread,pair_a,pair_b} # its own runs only
train() {  # name seed [env...]
  local name=$1 seed=$2; shift 2
  env "$@" .venv/bin/lerobot-train --policy.type=bc_rnn --policy.device=cpu --policy.push_to_hub=false \
    --dataset.repo_id=local/bench --dataset.root="$data" --output_dir="$out/$name" --steps="$steps" \
    --batch_size=100 --num_workers=2 --save_freq="$steps" --seed="$seed" --wandb.enable=false \
    > "$out/$name.log" 2>&1
}
rate() {  # the last progress-bar rate of a log
  tr '\r' '\n' < "$out/$1.log" | grep -o '[0-9.]*step/s' | tail -1
}
start=$(date +%s); train default 1000; echo "one training, default threads: $(rate default) ($(( $(date +%s) - start )) s)"
start=$(date +%s); train one_thread 1000 OMP_NUM_THREADS=1; echo "one training, 1 thread: $(rate one_thread) ($(( $(date +%s) - start )) s)"
start=$(date +%s)
train pair_a 1000 OMP_NUM_THREADS=1 & a=$!
train pair_b 1001 OMP_NUM_THREADS=1 & b=$!
wait $a $b
echo "two trainings at once, 1 thread each: $(rate pair_a) and $(rate pair_b) ($(( $(date +%s) - start )) s for both)"
