#!/usr/bin/env bash
# Does a longer training make Nut-and-Peg's base policy good enough to generate from? The table's
# base training command on its D, with STEPS steps (cosine over all of them, a checkpoint every
# STEPS/3), then each checkpoint's geometry-1 success over 30 trials (seed 777) and 12 IntervenGen
# attempts on geometry 2 from the last one (the table's generation seed 4; where each ends:
# benchmarks/nut_and_peg_ends.py). Needs the table's D and source interventions
# (bash benchmarks/paper_tables.sh nut_and_peg makes them first). One core, about 50 min at 15000 steps.
#
#   nice -n 10 bash benchmarks/bench_nut_and_peg_budget.sh 15000 outputs/nap_budget
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
steps=${1:-15000}
out=${2:-outputs/nap_budget}
table=${TABLE:-outputs/tables/nut_and_peg}
run="$out/base_$steps"
mkdir -p "$out"
portable=$(.venv/bin/python -m igen_lerobot.core.portable_math)  # the table's code paths
# a finished training is kept; an interrupted one is not resumed: remove $run and run this again
if [ ! -f "$run/checkpoints/$(printf '%06d' "$steps")/pretrained_model/config.json" ]; then
  env $portable OMP_NUM_THREADS=1 .venv/bin/lerobot-train --policy.type=bc_rnn --policy.device=cpu \
    --policy.push_to_hub=false --dataset.repo_id=local/base --dataset.root="$table/data/base" \
    --output_dir="$run" --steps="$steps" --batch_size=100 --num_workers=2 --save_freq=$((steps / 3)) \
    --seed=1000 --wandb.enable=false
fi
.venv/bin/igen-eval --env.type=nut_and_peg --env.geometry=1 --train_dir="$run" --every=1 --n_trials=30 \
  --seed=777 --policy.device=cpu --workers=1 --output="$out/geometry1_$steps.json"
last="$run/checkpoints/$(printf '%06d' "$steps")/pretrained_model"
.venv/bin/python benchmarks/nut_and_peg_ends.py --policy "$last" --geometry 2 --trials 12 --mode igen \
  --source "$table/data/source_int" --seed 4 | tee "$out/igen_geometry2_$steps.jsonl"
