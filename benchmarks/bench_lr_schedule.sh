#!/usr/bin/env bash
# Does annealing BC-RNN's learning rate make the chosen checkpoint matter less? (docs/results/reproducibility.md)
# The Nut Insertion I-Gen row, trained with 3 seeds on one dataset, once with robomimic's constant
# rate and once with --policy.lr_schedule=cosine; every run's five checkpoints are validated, the
# chosen one tested. The cosine table shares the constant table's data and base policy (links), so
# the two differ only in the schedule. Seeds run interleaved (constant 1000, cosine 1000, constant
# 1001, ...) so that a stopped study has pairs to compare; rerun the script to resume it.
# Cosine became BC-RNN's default after this study; the study's own runs were made while constant was
# (their table_config.json records no extra_args; each checkpoint's config.json records its schedule).
#
#   nice -n 10 bash benchmarks/bench_lr_schedule.sh [OUT_ROOT]      # default outputs/
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
root=${1:-outputs}
constant=$root/nut_repro
cosine=$root/nut_repro_cosine
bin=.venv/bin
table() {  # output dir, seeds, extra igen-table flags...
  local out=$1 seeds=$2; shift 2
  echo "$(date +%T) $out seeds $seeds"
  "$bin/igen-table" --task=nut_insertion --variants='[igen]' --train.steps=5000 --train.save_freq=1000 \
    "--train_seeds=$seeds" --output_dir="$out" --results="$out/results.md" "$@" >> "$out.log" 2>&1
}
mkdir -p "$constant" "$cosine/train"
for seeds in '[1000]' '[1000,1001]' '[1000,1001,1002]'; do
  table "$constant" "$seeds" '--train.extra_args=[--policy.lr_schedule=constant]'
  ln -sfn "$(realpath "$constant/data")" "$cosine/data"
  ln -sfn "$(realpath "$constant/train/base")" "$cosine/train/base"
  table "$cosine" "$seeds" '--train.extra_args=[--policy.lr_schedule=cosine]'
done
.venv/bin/python benchmarks/lr_schedule_summary.py "$constant" "$cosine"
