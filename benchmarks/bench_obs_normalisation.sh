#!/usr/bin/env bash
# Base policy of the Nut Insertion table trained three ways on the table's own base data (seed 1000,
# 5000 steps, one thread): LeRobot's mean/std (the default), mean/std with robomimic's 1e-3 added to
# each std, mean/std with std 1 for the inputs that never vary in the data, and no input
# normalisation (robomimic's default); each checkpoint tested on the table's 50 test trials. Needs outputs/tables/nut_insertion/data/base (the table's "base" step).
#   nice -n 10 bash benchmarks/bench_obs_normalisation.sh [out=outputs/obs_normalisation]
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
out=${1:-outputs/obs_normalisation}
export OMP_NUM_THREADS=1 MUJOCO_GL=egl HF_HUB_OFFLINE=1
train() {
  local name=$1; shift
  [ -d "$out/$name/checkpoints/005000" ] || .venv/bin/lerobot-train --policy.type=bc_rnn --policy.device=cpu \
    --policy.push_to_hub=false --dataset.repo_id=local/base --dataset.root=outputs/tables/nut_insertion/data/base \
    --output_dir="$out/$name" --steps=5000 --batch_size=100 --num_workers=2 --save_freq=1000 --seed=1000 \
    --wandb.enable=false "$@" > "$out/$name.train.log" 2>&1
  .venv/bin/igen-eval --env.type=nut_insertion --train_dir="$out/$name" --every=1 --n_trials=50 --seed=2000003 \
    > "$out/$name.eval.log" 2>&1
  grep -E "^(step|best)" "$out/$name.eval.log" | sed "s/^/$name: /"
}
mkdir -p "$out"
train mean_std --policy.constant_input_std=0 &  # LeRobot's own normalisation (the default before 2026-12-05)
train mean_std_tol --policy.constant_input_std=0 --policy.obs_std_tolerance=0.001 &
wait
train constant_std_1 --policy.constant_input_std=1.0 &
train identity '--policy.normalization_mapping={"STATE": "IDENTITY", "ENV": "IDENTITY", "ACTION": "MIN_MAX"}' &
wait
