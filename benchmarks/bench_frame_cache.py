r"""What the frame cache buys BC-RNN training: LeRobot's reader against ``CachedFrameReader``.

    .venv/bin/python benchmarks/bench_frame_cache.py --root outputs/table_nut_full/data/train_source_int \
        --samples 300 --train_steps 200

On one dataset: (1) seconds per ``LeRobotDataset[i]`` with BC-RNN's window (``horizon`` frames of
every observation and the action) on the same random indices with LeRobot's reader, the cache
holding only the windows, and the whole cache, and whether every sample is identical;
(2) ``lerobot-train --policy.type=bc_rnn`` for ``--train_steps`` steps at the table's settings
(batch 100, 2 loader workers) with ``IGEN_FRAME_CACHE=1`` and ``=0``: mean steps/s of its training
loop (tqdm's elapsed time, loader start-up included), wall time, and whether the saved weights are
bit-identical.
Run it on an idle machine; prints one JSON object.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import torch


def sample_seconds(root: Path, samples: int, reader: str) -> tuple[float, list[dict]]:
    """Seconds per sample with ``reader``: "lerobot", "windows" (only windows held) or "cached"."""
    from lerobot.datasets import lerobot_dataset
    from lerobot.datasets.dataset_reader import DatasetReader

    from igen_lerobot.training import frame_cache
    from igen_lerobot.training.bc_rnn import BCRNNConfig

    class WindowsOnlyReader(frame_cache.CachedFrameReader):
        def _rows_for(self, hf_dataset):
            return None  # each sample's row and episode bounds from LeRobot's lookups

    readers = {"lerobot": DatasetReader, "windows": WindowsOnlyReader, "cached": frame_cache.CachedFrameReader}
    lerobot_dataset.DatasetReader = readers[reader]
    meta = lerobot_dataset.LeRobotDataset("local/bench", root=root).meta
    horizon = BCRNNConfig().horizon
    keys = [k for k in meta.features if k.startswith("observation.") or k == "action"]
    deltas = {k: [i / meta.fps for i in range(horizon)] for k in keys}
    dataset = lerobot_dataset.LeRobotDataset("local/bench", root=root, delta_timestamps=deltas)
    indices = np.random.default_rng(0).integers(0, len(dataset), samples)
    dataset[0]  # the first access loads (and, cached, builds the columns): not what a step costs
    start = time.perf_counter()
    items = [dataset[int(i)] for i in indices]
    return (time.perf_counter() - start) / samples, items


def same_items(a: list[dict], b: list[dict]) -> bool:
    for x, y in zip(a, b, strict=True):
        for key, value in x.items():
            other = y[key]
            if isinstance(value, torch.Tensor):
                if value.dtype != other.dtype or value.shape != other.shape or not torch.equal(value, other):
                    return False
            elif value != other:
                return False
    return True


def train(root: Path, output_dir: Path, steps: int, cache: str) -> dict:
    command = [
        os.path.join(os.path.dirname(sys.executable), "lerobot-train"),
        "--policy.type=bc_rnn", "--policy.device=cpu", "--policy.push_to_hub=false",
        "--dataset.repo_id=local/bench", f"--dataset.root={root}", f"--output_dir={output_dir}",
        f"--steps={steps}", "--batch_size=100", "--num_workers=2", f"--save_freq={steps}", "--seed=1000",
        "--wandb.enable=false",
    ]  # fmt: skip
    start = time.perf_counter()
    run = subprocess.run(command, capture_output=True, text=True, env={**os.environ, "IGEN_FRAME_CACHE": cache})
    wall = time.perf_counter() - start
    if run.returncode != 0:
        raise SystemExit(f"lerobot-train failed:\n{run.stderr[-3000:]}")
    minutes, seconds = re.findall(rf"Training: 100%.*?{steps}/{steps} \[(\d+):(\d+)<", run.stderr)[-1]
    loop_s = 60 * int(minutes) + int(seconds)  # tqdm's elapsed time of the training loop (whole seconds)
    steps_per_s = round(steps / loop_s, 2)
    return {"wall_s": round(wall, 1), "loop_s": loop_s, "steps_per_s": steps_per_s, "output_dir": output_dir}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--root", type=Path, required=True, help="a LeRobot dataset written by igen")
    parser.add_argument("--samples", type=int, default=300)
    parser.add_argument("--train_steps", type=int, default=200)
    args = parser.parse_args()

    plain_s, plain_items = sample_seconds(args.root, args.samples, "lerobot")
    windows_s, windows_items = sample_seconds(args.root, args.samples, "windows")
    cached_s, cached_items = sample_seconds(args.root, args.samples, "cached")
    report = {
        "root": str(args.root),
        "sample_ms": {
            k: round(v * 1e3, 3) for k, v in (("lerobot", plain_s), ("windows_only", windows_s), ("cached", cached_s))
        },
        "sample_speedup": round(plain_s / cached_s, 1),
        "samples_identical": same_items(plain_items, cached_items) and same_items(plain_items, windows_items),
    }
    if args.train_steps > 0:
        from safetensors.torch import load_file

        with tempfile.TemporaryDirectory() as tmp:
            runs = {cache: train(args.root, Path(tmp) / f"cache{cache}", args.train_steps, cache) for cache in "10"}
            name = f"checkpoints/{args.train_steps:06d}/pretrained_model/model.safetensors"
            weights = [load_file(runs[c].pop("output_dir") / name) for c in "10"]
        report["lerobot_train"] = {"cached": runs["1"], "lerobot": runs["0"]}
        report["train_speedup"] = round(runs["1"]["steps_per_s"] / runs["0"]["steps_per_s"], 1)
        report["weights_identical"] = weights[0].keys() == weights[1].keys() and all(
            torch.equal(weights[0][k], weights[1][k]) for k in weights[0]
        )
    print(json.dumps(report, indent=1))


if __name__ == "__main__":
    main()
