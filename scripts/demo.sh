#!/usr/bin/env bash
# The embedded default: Block Grasp with the scripted operator standing in for a person.
# 1) 10 full demonstrations on true poses, 2) 10 human-gated interventions on corrupted poses.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
out=${IGEN_DEMO_OUT:-outputs/demo}
bin=.venv/bin
$bin/igen-collect --env.type=block_grasp --mode=demos --num_episodes=10 --seed=0 \
  --dataset.repo_id=local/block_grasp_source_demos --dataset.root="$out/source_demos" --dataset.overwrite=true
$bin/igen-collect --env.type=block_grasp --mode=interventions --num_episodes=10 --seed=1 \
  --dataset.repo_id=local/block_grasp_source_interventions --dataset.root="$out/source_interventions" --dataset.overwrite=true
echo "demo: datasets in $out (read them with lerobot.datasets.lerobot_dataset.LeRobotDataset)"
