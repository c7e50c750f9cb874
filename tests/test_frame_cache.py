"""The frame cache gives LeRobot's own samples: every key (in LeRobot's order), dtype and padding
flag, whether the whole sample or only its windows come from memory, and the same trained weights through
``lerobot-train`` (spawned loader workers included)."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
import torch
from lerobot.datasets import lerobot_dataset
from lerobot.datasets.dataset_reader import DatasetReader
from lerobot.datasets.lerobot_dataset import LeRobotDataset
from safetensors.torch import load_file

from igen_lerobot.training import frame_cache

FPS = 20
BOOKKEEPING = {"episode_index", "task_index"}  # read as scalars by LeRobot's __getitem__ itself


@pytest.fixture()
def upstream_reader(monkeypatch):
    """LeRobot's reader for datasets made in the test (the plugin installs the cache at import)."""
    monkeypatch.setattr(lerobot_dataset, "DatasetReader", DatasetReader)


def _windows(root, episodes=None, cached=False) -> LeRobotDataset:
    meta = LeRobotDataset("local/windows", root=root).meta
    numeric = {k for k, f in meta.features.items() if f["dtype"] not in ("video", "image", "string")}
    keys = sorted(numeric - BOOKKEEPING)
    deltas = {k: [i / FPS for i in range(-3, 10)] for k in keys}  # past frames padded, future ones too
    if cached:
        frame_cache.install()
    return LeRobotDataset("local/windows", root=root, episodes=episodes, delta_timestamps=deltas)


@pytest.mark.parametrize("episodes", [None, [1, 3]], ids=["all episodes", "episodes 1 and 3"])
def test_cached_windows_equal_lerobots_for_every_key(source_demos, upstream_reader, episodes):
    upstream = _windows(source_demos, episodes)
    cached = _windows(source_demos, episodes, cached=True)
    assert isinstance(cached.reader, frame_cache.CachedFrameReader)
    assert not isinstance(upstream.reader, frame_cache.CachedFrameReader)
    assert cached.reader._rows_for(cached.reader.hf_dataset) is not None  # whole samples from memory
    n = len(upstream)
    picks = sorted({0, 1, n - 1, *np.random.default_rng(0).integers(0, n, 40).tolist()})
    for i in picks:
        a, b = upstream[i], cached[i]
        assert list(a) == list(b), i  # the same keys in the same order
        for key, value in a.items():
            if isinstance(value, torch.Tensor):
                assert value.dtype == b[key].dtype and value.shape == b[key].shape, (i, key)
                assert torch.equal(value, b[key]), (i, key)
            else:
                assert value == b[key], (i, key)
    assert upstream[0]["action_is_pad"][:3].all()  # the window really reached across an episode start


def test_columns_too_large_to_hold_stay_on_lerobots_path(source_demos, upstream_reader, monkeypatch):
    upstream = _windows(source_demos)
    monkeypatch.setattr(frame_cache, "MAX_COLUMN_BYTES", 0)
    cached = _windows(source_demos, cached=True)
    for i in (0, len(upstream) // 2):
        a, b = upstream[i], cached[i]
        assert all(torch.equal(a[k], b[k]) for k in a if isinstance(a[k], torch.Tensor))
    assert cached.reader._columns_for(cached.reader.hf_dataset) == {}
    assert cached.reader._rows_for(cached.reader.hf_dataset) is None  # the row comes from LeRobot's lookup too


def test_switched_off_by_environment(monkeypatch, upstream_reader):
    monkeypatch.setenv(frame_cache.ENV_SWITCH, "0")
    assert not frame_cache.install()
    assert not frame_cache.installed()


def _train(root, output_dir, cache: str) -> dict:
    command = [
        os.path.join(os.path.dirname(sys.executable), "lerobot-train"),
        "--policy.type=bc_rnn", "--policy.device=cpu", "--policy.push_to_hub=false",
        "--dataset.repo_id=local/frame_cache", f"--dataset.root={root}", f"--output_dir={output_dir}",
        "--steps=4", "--batch_size=16", "--num_workers=2", "--save_freq=4", "--seed=7", "--wandb.enable=false",
    ]  # fmt: skip
    run = subprocess.run(command, capture_output=True, text=True, env={**os.environ, frame_cache.ENV_SWITCH: cache})
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-2000:]
    weights = load_file(output_dir / "checkpoints" / "000004" / "pretrained_model" / "model.safetensors")
    return weights


def test_lerobot_train_learns_the_same_weights_with_and_without_the_cache(source_demos, tmp_path):
    cached = _train(source_demos, tmp_path / "cached", "1")
    plain = _train(source_demos, tmp_path / "plain", "0")
    assert cached.keys() == plain.keys()
    for key, value in cached.items():
        assert torch.equal(value, plain[key]), key


@pytest.mark.parametrize("switch", ["1", "0"])
def test_lerobots_plugin_discovery_installs_the_cache_unless_switched_off(switch):
    """What lerobot-train does before it makes its dataset: import every lerobot_policy_* package."""
    script = (
        "from lerobot.utils.import_utils import register_third_party_plugins\n"
        "from lerobot.datasets import lerobot_dataset\n"
        "register_third_party_plugins()\n"
        "print(lerobot_dataset.DatasetReader.__name__)\n"
    )
    env = {**os.environ, frame_cache.ENV_SWITCH: switch}
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, check=True)
    assert run.stdout.split()[-1] == ("CachedFrameReader" if switch == "1" else "DatasetReader")
