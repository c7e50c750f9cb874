#!/usr/bin/env bash
# The embedded default: Block Grasp with the scripted operator standing in for a person.
# 1) 10 full demonstrations on true poses, 2) 10 human-gated interventions on corrupted poses.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
out=${IGEN_DEMO_OUT:-outputs/datasets}
.venv/bin/igen-collect --config_path=datasets/recipes/block_grasp_source_demos.yaml \
  --dataset.root="$out/block_grasp_source_demos" --dataset.overwrite=true
.venv/bin/igen-collect --config_path=datasets/recipes/block_grasp_source_interventions.yaml \
  --dataset.root="$out/block_grasp_source_interventions" --dataset.overwrite=true
echo "demo: source datasets written under $out/"
