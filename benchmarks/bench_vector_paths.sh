#!/usr/bin/env bash
# Does the vector unit change a training's weights? Four 40-step BC-RNN trainings (seed 1000, one
# thread) on one small Block Grasp dataset, differing only in the code paths torch, MKL and oneDNN
# may take: as installed, pinned to AVX2, forced to the generic paths, and igen-table's portable
# paths. Prints which weights are identical to the plain ones, and a digest of each, so that two
# hosts can be compared
# (docs/results/reproducibility.md). The demonstrations are made on the portable code paths
# (igen_lerobot/core/portable_math.py), so every host trains on the same bytes.
#
#   bash benchmarks/bench_vector_paths.sh [output_dir]     # default outputs/vector_paths
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
out=${1:-outputs/vector_paths}
mkdir -p "$out"
if [ ! -e "$out/demos/meta/igen.json" ]; then
  rm -rf "$out/demos"
  env $(.venv/bin/python -m igen_lerobot.core.portable_math) \
    .venv/bin/igen-collect --env.type=block_grasp --mode=demos --num_episodes=4 --dataset.root="$out/demos"
fi
declare -A CODE_PATHS=(
  [plain]=""
  [avx2]="ATEN_CPU_CAPABILITY=avx2 MKL_CBWR=AVX2 ONEDNN_MAX_CPU_ISA=AVX2"
  [generic]="ATEN_CPU_CAPABILITY=default MKL_CBWR=COMPATIBLE ONEDNN_MAX_CPU_ISA=SSE41"
  [portable]="$(.venv/bin/python -m igen_lerobot.core.portable_math)"  # what igen-table's steps run with
)
for name in plain avx2 generic portable; do
  rm -rf "${out:?}/$name"
  echo "training with code paths '$name': ${CODE_PATHS[$name]:-(as installed)}"
  # shellcheck disable=SC2086 # the settings are words
  env OMP_NUM_THREADS=1 ${CODE_PATHS[$name]} .venv/bin/python -c '
import sys
from pathlib import Path
from igen_lerobot.training.config_train import TrainConfig
from igen_lerobot.training.lerobot_train import lerobot_train
cfg = TrainConfig(policy_type="bc_rnn", steps=40, batch_size=16, num_workers=0, save_freq=40, seed=1000)
lerobot_train(cfg, Path(sys.argv[1]), "local/demos", Path(sys.argv[2]))
' "$out/demos" "$out/$name" > "$out/$name.log" 2>&1
done
.venv/bin/python - "$out" <<'PY'
import hashlib
import sys
from pathlib import Path

import torch
from safetensors.torch import load_file

from igen_lerobot.experiments.training_reuse import dataset_digest

out = Path(sys.argv[1])
weights = {n: load_file(next((out / n / "checkpoints").glob("*/pretrained_model/model.safetensors"))) for n in ("plain", "avx2", "generic", "portable")}
print(f"torch's own choice here: {torch.backends.cpu.get_cpu_capability()}")
print(f"demonstrations: digest {dataset_digest(out / 'demos')[:12]}")
for name, tensors in weights.items():
    digest = hashlib.sha256(b"".join(k.encode() + tensors[k].numpy().tobytes() for k in sorted(tensors)))
    print(f"{name}: weights digest {digest.hexdigest()[:12]}")
for name in ("avx2", "generic", "portable"):
    same = all(torch.equal(weights["plain"][k], weights[name][k]) for k in weights["plain"])
    largest = max((weights["plain"][k] - weights[name][k]).abs().max().item() for k in weights["plain"])
    print(f"{name} vs plain: {'identical' if same else f'differ, largest difference {largest:.1e}'}")
PY
