#!/usr/bin/env bash
# Does robomimic 0.3.0 read what igen-export writes? Fresh Block Grasp demonstrations (igen-collect),
# exported with igen-export, read with robomimic's own SequenceDataset (load_next_obs=True,
# filter_by_attribute=train / valid / all) in a throwaway venv that holds robomimic and no igen
# code; every sequence (obs, next_obs, actions, rewards, dones, padding) is compared with the
# igen dataset's episodes (benchmarks/bench_robomimic_reader.py says how).
#
#   MUJOCO_GL=egl bash benchmarks/bench_robomimic_reader.sh [output folder]   # ~4 min on 2 cores
#
# robomimic 0.3.0 is installed without its declared dependencies (among them egl_probe, a CMake
# build, and tensorboard): its dataset module imports only torch, numpy, h5py, tqdm and termcolor;
# file_utils and scripts/split_train_val.py (used here for robomimic's own split and shapes) also
# need six (imported, never declared), torchvision and matplotlib. Versions are the project's
# locked ones, so uv links them from its cache. PyPI's Linux torch is its CUDA build; the check
# runs it on the CPU (CUDA_VISIBLE_DEVICES=""). BENCH_TORCH overrides the torch requirement.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
out=${1:-outputs/bench_robomimic_reader}
bin=.venv/bin
mkdir -p "$out"
out=$(cd "$out" && pwd)

torch_version=$("$bin/python" -c 'import torch; print(torch.__version__.split("+")[0])')
vision_version=$("$bin/python" -c 'import torchvision; print(torchvision.__version__.split("+")[0])')
pin() { "$bin/python" -c "from importlib.metadata import version; print('$1==' + version('$1'))"; }
venv="$out/robomimic-venv"
rm -rf "$venv"
export UV_PYTHON_DOWNLOADS=never
uv venv -q --python "$("$bin/python" -c 'import sys; print(sys._base_executable)')" "$venv"
uv pip install -q --python "$venv/bin/python" --no-deps robomimic==0.3.0
uv pip install -q --python "$venv/bin/python" six==1.17.0 termcolor==3.3.0 "$(pin h5py)" "$(pin numpy)" \
  "$(pin tqdm)" "$(pin matplotlib)" "${BENCH_TORCH:-torch==$torch_version}" "torchvision==$vision_version"

# three datasets: 10 demos (robomimic's script would pick 1 validation demo too), 3 (it would pick
# none; we pick one), 1 (train only, valid empty)
for n in 10 3 1; do
  [ -e "$out/demos_$n" ] || "$bin/igen-collect" --env.type=block_grasp --mode=demos --num_episodes="$n" --seed=0 \
    --dataset.root="$out/demos_$n" >"$out/collect_$n.log" 2>&1
  "$bin/python" benchmarks/bench_robomimic_reader.py expected --dataset="$out/demos_$n" --out="$out/demos_$n.npz"
done

check() {  # dataset, file name, export flags...
  local n=$1 name=$2
  shift 2
  "$bin/igen-export" --format=robomimic --dataset.root="$out/demos_$n" --output="$out/$name.hdf5" --overwrite=true "$@" \
    2>/dev/null | tail -2
  local fraction=0.1 seed=0
  for flag in "$@"; do
    case $flag in --valid_fraction=*) fraction=${flag#*=} ;; --split_seed=*) seed=${flag#*=} ;; esac
  done
  CUDA_VISIBLE_DEVICES="" "$venv/bin/python" benchmarks/bench_robomimic_reader.py check --hdf5="$out/$name.hdf5" \
    --expected="$out/demos_$n.npz" --valid_fraction="$fraction" --split_seed="$seed" 2>"$out/$name.err" |
    tee "$out/$name.json"
}
check 10 demos_10
check 10 demos_10_f03_s1 --valid_fraction=0.3 --split_seed=1
check 3 demos_3
check 1 demos_1
[ -n "${KEEP_VENV:-}" ] || rm -rf "$venv"
