#!/usr/bin/env bash
# The embedded default main job: IntervenGen on Block Grasp, scripted operator as the person.
#
#   1. 10 source demonstrations (operator on true poses)                     igen-collect
#   2. MimicGen demonstrations from them: the base dataset D                 igen-generate --mode=mimicgen
#   3. one iteration of Algorithm 1 on D                                     igen-loop
#      train the base policy (BC-RNN, lerobot-train) -> 10 human-gated interventions on it
#      -> IntervenGen interventions with it -> D + generated
#
# Sizes (environment variables): IGEN_DEMO_MG (MimicGen demos, default 200), IGEN_DEMO_GENERATED
# (IntervenGen interventions, default 1000), IGEN_DEMO_TRAIN_STEPS (BC-RNN steps, default 500),
# IGEN_DEMO_WORKERS (default 2). Re-running resumes; outputs go to $IGEN_DEMO_OUT (outputs/demo).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
out=${IGEN_DEMO_OUT:-outputs/demo}
mg=${IGEN_DEMO_MG:-200}
generated=${IGEN_DEMO_GENERATED:-1000}
steps=${IGEN_DEMO_TRAIN_STEPS:-500}
workers=${IGEN_DEMO_WORKERS:-2}
bin=.venv/bin

if [ ! -f "$out/source_demos/meta/igen.json" ]; then
  $bin/igen-collect --config_path=datasets/recipes/collect_block_grasp_demos.yaml \
    --dataset.root="$out/source_demos"
fi
if [ ! -f "$out/mg_demos/meta/igen.json" ]; then
  $bin/igen-generate --config_path=datasets/recipes/generate_block_grasp_mimicgen.yaml \
    --source.root="$out/source_demos" --num_episodes="$mg" --workers="$workers" --dataset.root="$out/mg_demos"
fi
$bin/igen-loop --task=block_grasp --base_dataset="$out/mg_demos" --iterations=1 --interventions=10 \
  --generated="$generated" --workers="$workers" --train.policy_type=bc_rnn --train.steps="$steps" \
  --train_final=false --output_dir="$out/loop"

cat <<MSG

demo: done. The IntervenGen dataset (MimicGen demos + generated interventions) is
  $out/loop/iter_0/dataset
Train on it (inputs normalised with D's statistics, as igen-table does) and evaluate under the
paper's pose error:
  $bin/lerobot-train --policy.type=bc_rnn --policy.device=cpu --policy.push_to_hub=false \\
      --dataset.repo_id=local/dataset --dataset.root=$out/loop/iter_0/dataset --output_dir=outputs/train/igen \\
      --policy.observation_stats=$out/mg_demos
  MUJOCO_GL=egl $bin/lerobot-eval --env.type=block_grasp --policy.path=outputs/train/igen/checkpoints/last/pretrained_model \\
      --policy.device=cpu --eval.n_episodes=50 --eval.batch_size=1 --output_dir=outputs/eval/igen
MSG
