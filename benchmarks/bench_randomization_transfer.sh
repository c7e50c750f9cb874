#!/usr/bin/env bash
# Does generating with a randomised arm make the Block Grasp I-Gen policy transfer better?
# Takes a finished `igen-table --task=block_grasp --variants='[igen]' --train_seeds='[1000]'` run
# (its 10 source demonstrations and interventions, its base policy, its I-Gen checkpoint) and makes
# the same row again with only one change: D (1000 MimicGen demos) and the 1000 IntervenGen
# episodes are generated with the randomisation SETTING on (a name in randomization_settings.sh:
# `all`, the default, or one flag alone, e.g. `kp_0.5-1.5`). Same sources, base policy, seeds,
# training settings, validation and test trials. Then both I-Gen checkpoints go through
# igen-eval (the training arm) and the rehearsal (bench_rehearsal.sh: the MuJoCo arm and franky on
# franky-sim, the trials igen-eval runs with --compare_sim).
#
#   MUJOCO_GL=egl bash benchmarks/bench_randomization_transfer.sh outputs/bg_igen1 outputs/bg_igen_rand [TRIALS] [SETTING]
# The table's own I-Gen checkpoint is rehearsed once per pace clock, into TABLE_DIR/rehearsal_igen_<pace>, and
# reused by every setting. PACE_ON=arm|wall (default arm): the clock franky's 20 Hz periods are measured on
# (igen-deploy --pace_on); franky-sim's own runs slower than the wall clock. TRAIN_SEED (default 1000): the
# randomised row's training seed; another seed trains on the same data into train/igen_seed<N> and
# validates, tests and rehearses into files with the same suffix (the plain checkpoint stays seed 1000's).
# REHEARSE=0 stops after the test trials: train beside other jobs, rehearse later on an idle machine.
# RUN_SUFFIX names the run's files instead of _seed<N> (e.g. _cosine_seed1001 for a run under another
# training setting, TRAIN_ARGS, given to lerobot-train: TRAIN_ARGS=--policy.lr_schedule=cosine).
# TRAIN_STEPS (default 2000) and SAVE_FREQ (default 500): a longer budget, checkpoints validated as before.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
table=${1:?usage: bench_randomization_transfer.sh TABLE_DIR OUT_DIR [TRIALS]}
out=${2:?usage: bench_randomization_transfer.sh TABLE_DIR OUT_DIR [TRIALS]}
trials=${3:-20}
setting=${4:-all}
train_seed=${TRAIN_SEED:-1000}
suffix=""
[ "$train_seed" = 1000 ] || suffix=_seed$train_seed
suffix=${RUN_SUFFIX:-$suffix}
read -r -a train_args <<< "${TRAIN_ARGS:-}"
train_steps=${TRAIN_STEPS:-2000}
save_freq=${SAVE_FREQ:-500}
bin=.venv/bin
source benchmarks/randomization_settings.sh
[ -n "${RANDOMIZE_SETTINGS[$setting]+set}" ] && [ "$setting" != none ] \
  || { echo "SETTING must be one of ${RANDOMIZE_ORDER[*]:1}, got '$setting'"; exit 2; }
read -r -a randomize <<< "${RANDOMIZE_SETTINGS[$setting]}"
echo "$(date +%T) $out: generation randomised with ${randomize[*]}"
base_policy="$table/train/base/seed1000/checkpoints/last/pretrained_model"
mkdir -p "$out/data" "$out/eval"
step() {  # name, done-marker, command...: skipped once its output is complete
  local name=$1 done=$2; shift 2
  [ -e "$done" ] && return
  echo "$(date +%T) $name: $*"
  "$@" > "$out/$name.log" 2>&1
}
step base "$out/data/base/meta/igen.json" "$bin/igen-generate" --mode=mimicgen --env.type=block_grasp "${randomize[@]}" \
  --source.root="$table/data/source_demos" --num_episodes=1000 --seed=0 --workers=2 --dataset.root="$out/data/base"
if [ ! -e "$table/data/source_int/meta/igen.json" ] || [ ! -e "$base_policy/config.json" ]; then
  echo "$table has no source interventions or base policy yet: finish its igen-table run, then rerun this"; exit 1
fi
step igen "$out/data/igen/meta/igen.json" "$bin/igen-generate" --mode=igen --env.type=block_grasp "${randomize[@]}" \
  --source.root="$table/data/source_int" --num_episodes=1000 --seed=4 --workers=2 --policy.path="$base_policy" \
  --dataset.root="$out/data/igen"
step merge "$out/data/train_igen/meta/igen.json" "$bin/igen-merge" --task=block_grasp \
  "--inputs=[$out/data/base,$out/data/igen]" --dataset.root="$out/data/train_igen"
run=$out/train/igen$suffix
step "train$suffix" "$(printf '%s/checkpoints/%06d/pretrained_model/config.json' "$run" "$train_steps")" \
  "$bin/lerobot-train" --policy.type=bc_rnn \
  --policy.device=cpu --policy.push_to_hub=false --dataset.repo_id=local/train_igen \
  --dataset.root="$out/data/train_igen" --output_dir="$run" --steps="$train_steps" --batch_size=100 --num_workers=2 \
  --save_freq="$save_freq" --seed="$train_seed" --wandb.enable=false "${train_args[@]}"
validation=$out/eval/validation$suffix.json
test=$out/eval/test$suffix.json
step "validate$suffix" "$validation" "$bin/igen-eval" --env.type=block_grasp --train_dir="$run" \
  --n_trials=20 --seed=1000003 --output="$validation"
chosen=$("$bin/python" -c "import json,sys; print(json.load(open(sys.argv[1]))['best']['step'])" "$validation")
checkpoint=$(printf '%s/checkpoints/%06d/pretrained_model' "$run" "$chosen")
step "test$suffix" "$test" "$bin/igen-eval" --env.type=block_grasp --policy.path="$checkpoint" --n_trials=50 \
  --seed=2000003 --output="$test"
plain=$("$bin/python" - "$table" <<'PY'
import sys
from igen_lerobot.experiments.table import chosen_checkpoint
print(chosen_checkpoint(sys.argv[1], "igen", 1000)[1])
PY
)
[ "${REHEARSE:-1}" = 1 ] || exit 0
pace=${PACE_ON:-arm}
plain_rehearsal=$table/rehearsal_igen_$pace  # the table's own checkpoint: rehearsed once, whatever the setting
randomised_rehearsal=$out/rehearsal_randomised_$pace$suffix
[ -e "$plain_rehearsal/franky.json" ] || bash benchmarks/bench_rehearsal.sh "$plain" "$trials" "$plain_rehearsal" --pace_on="$pace"
[ -e "$randomised_rehearsal/franky.json" ] \
  || bash benchmarks/bench_rehearsal.sh "$checkpoint" "$trials" "$randomised_rehearsal" --pace_on="$pace"
echo "plain I-Gen ($plain):"
"$bin/python" benchmarks/rehearsal_summary.py "$plain_rehearsal/mujoco.json" "$plain_rehearsal/franky.json"
echo "randomised I-Gen ($checkpoint), test trials: $("$bin/python" -c "import json,sys; b=json.load(open(sys.argv[1]))['best']; print(b['successes'], '/', b['trials'])" "$test")"
"$bin/python" benchmarks/rehearsal_summary.py "$randomised_rehearsal/mujoco.json" "$randomised_rehearsal/franky.json"
