#!/usr/bin/env bash
# A picture of one IntervenGen-generated recovery of a task, from nothing, in one command:
#
#   bash scripts/recovery_picture.sh coffee            # -> docs/images/coffee_recovery.png
#   bash scripts/recovery_picture.sh two_piece_assembly
#
# 1. 3 human-gated interventions by the scripted operator on the scripted base policy  igen-collect
# 2. 2 IntervenGen interventions from them (new scene, new error, the policy's own
#    mistake, a source recovery moved into the object's true frame)                    igen-generate
# 3. the first generated episode drawn like the Rerun views: path from above, believed
#    and true object, height over time, the recovery's frames in orange               igen_lerobot.viz.picture
#
# Outputs go to $IGEN_PICTURE_OUT (outputs/pictures/<task>); re-running reuses what is there.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
task=${1:?"usage: scripts/recovery_picture.sh TASK (block_grasp, nut_insertion, two_piece_assembly, coffee)"}
out=${IGEN_PICTURE_OUT:-outputs/pictures/$task}
bin=.venv/bin

if [ ! -f "$out/interventions/meta/igen.json" ]; then
  $bin/igen-collect --env.type="$task" --mode=interventions --num_episodes=3 --seed=0 \
    --dataset.root="$out/interventions"
fi
if [ ! -f "$out/generated/meta/igen.json" ]; then
  $bin/igen-generate --mode=igen --env.type="$task" --source.root="$out/interventions" --num_episodes=2 \
    --workers=1 --seed=0 --dataset.root="$out/generated"
fi
$bin/python -m igen_lerobot.viz.picture --root "$out/generated" --episode 0 --output "docs/images/${task}_recovery.png"
