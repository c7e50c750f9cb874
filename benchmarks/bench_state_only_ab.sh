#!/usr/bin/env bash
# State-only generation, this checkout against another release (its own checkout with its own
# environment, both compiled to bytecode by scripts/setup.sh), alternating, 3 rounds:
#   bash benchmarks/bench_state_only_ab.sh /path/to/old/checkout /path/to/source_demos [episodes]
# Prints each run's generation phase (run_generation's seconds and env steps/s) and its dataset write.
set -euo pipefail
old=$1 sources=$2 episodes=${3:-100}
new=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
out=$(mktemp -d)
for round in 1 2 3; do
  for side in old new; do
    dir=$old; [ "$side" = new ] && dir=$new
    log="$out/${side}_$round.log"
    (cd "$dir" && MUJOCO_GL=egl .venv/bin/igen-generate --mode=mimicgen --task=block_grasp \
      --source.root="$sources" --num_episodes="$episodes" --workers=2 --seed=7 \
      --dataset.root="$out/${side}_$round" >"$log" 2>&1)
    gen=$(grep -o "frames, [0-9.]* s, [0-9]* env steps/s" "$log" | sed 's/frames, //')
    write=$(grep -o "wrote $episodes episodes ([0-9]* frames) to [^ ]* in [0-9.]* s" "$log" | grep -o "in [0-9.]* s")
    echo "$side round $round: generation $gen; write $write"
  done
done
rm -rf "$out"
