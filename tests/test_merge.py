"""igen-merge: aggregation through LeRobot, and the weighting behind "Weighted Src Int"."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from lerobot.datasets.lerobot_dataset import LeRobotDataset

from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.datasets.merge import weighted_repeats
from igen_lerobot.datasets.schema import IS_INTERVENTION, dataset_features

BIN = Path(sys.executable).parent
ENV = {**os.environ, "MUJOCO_GL": "egl", "HF_HUB_OFFLINE": "1"}


def test_weighted_repeats():
    assert weighted_repeats([6000, 100], [1, 1]) == [1, 60]
    assert weighted_repeats([6000, 100], [1, 0.5]) == [1, 30]
    assert weighted_repeats([6000, 100, 3000], [2, 1, 1]) == [1, 30, 1]
    assert weighted_repeats([100, 6000], [1, 1]) == [1, 1]  # never fewer than one copy
    with pytest.raises(ConfigError, match="one per dataset"):
        weighted_repeats([10, 10], [1])
    with pytest.raises(ConfigError, match="> 0"):
        weighted_repeats([10, 10], [1, 0])


def _merge(*args):
    return subprocess.run(
        [str(BIN / "igen-merge"), "--task=block_grasp", *args], capture_output=True, text=True, timeout=300, env=ENV
    )


def test_weighted_merge_samples_interventions_as_often_as_the_base(source_demos, source_interventions, tmp_path):
    out = tmp_path / "weighted"
    result = _merge(f"--inputs=[{source_demos},{source_interventions}]", "--weights=[1,3]", f"--dataset.root={out}")
    assert result.returncode == 0, result.stderr[-3000:]
    base = LeRobotDataset("local/b", root=source_demos)
    interventions = LeRobotDataset("local/i", root=source_interventions)
    repeats = weighted_repeats([base.meta.total_frames, interventions.meta.total_frames], [1, 3])[1]
    assert repeats >= 2
    merged = LeRobotDataset("local/w", root=out)  # LeRobot's own loader reads it
    assert merged.meta.total_episodes == base.meta.total_episodes + repeats * interventions.meta.total_episodes
    assert merged.meta.total_frames == base.meta.total_frames + repeats * interventions.meta.total_frames
    # the flags travel with the copies: flagged frames are exactly `repeats` times the source's
    flags = np.asarray(merged.hf_dataset.with_format("numpy")[IS_INTERVENTION]).sum()
    source_flags = np.asarray(interventions.hf_dataset.with_format("numpy")[IS_INTERVENTION]).sum()
    assert flags == repeats * source_flags
    # the intervention part's share of frames follows the weights (3:1) up to the rounding of `repeats`
    share = repeats * interventions.meta.total_frames / merged.meta.total_frames
    target = 3 / 4
    assert abs(share - target) < interventions.meta.total_frames / merged.meta.total_frames
    meta = json.loads((out / "meta" / "igen.json").read_text())
    assert [p["repeats"] for p in meta["parts"]] == [1, repeats]
    # the fixtures record no origin (created_by "test"): the merge says so rather than guessing
    assert [p["origin"] for p in meta["parts"]] == [{"kind": None}, {"kind": None}]
    assert meta["origin"] == {"kind": "merge", "source_kinds": [None]}
    assert meta["episode_kinds"]["intervention"] == repeats * interventions.meta.total_episodes


def test_merge_bad_input_names_the_field(source_demos, tmp_path):
    mismatch = _merge(f"--inputs=[{source_demos},{source_demos}]", "--weights=[1]", f"--dataset.root={tmp_path / 'x'}")
    assert mismatch.returncode == 2 and "--weights has 1 entries for 2 --inputs" in mismatch.stderr
    missing = _merge(f"--inputs=[{source_demos},{tmp_path / 'nope'}]", f"--dataset.root={tmp_path / 'y'}")
    assert missing.returncode == 2 and "not a LeRobot dataset" in missing.stderr
    assert not (tmp_path / "x").exists() and not (tmp_path / "y").exists()


def test_merge_rejects_empty_and_flagless_datasets(source_demos, tmp_path):
    from lerobot_env_igen.block_grasp.spec import SPEC

    features = {k: v for k, v in dataset_features(SPEC).items() if not k.startswith("complementary_info")}
    plain = LeRobotDataset.create("local/plain", fps=20, features=features, root=tmp_path / "plain", use_videos=False)
    plain.add_frame({k: np.zeros(v["shape"], dtype=v["dtype"]) for k, v in features.items()} | {"task": "x"})
    plain.save_episode()
    plain.finalize()
    flagless = _merge(f"--inputs=[{source_demos},{tmp_path / 'plain'}]", f"--dataset.root={tmp_path / 'a'}")
    assert flagless.returncode == 2 and "without igen metadata" in flagless.stderr

    empty = LeRobotDataset.create(
        "local/empty", fps=20, features=dataset_features(SPEC), root=tmp_path / "empty", use_videos=False
    )
    empty.finalize()
    (tmp_path / "empty" / "meta" / "igen.json").write_text(json.dumps({"task": "block_grasp"}))
    no_episodes = _merge(f"--inputs=[{source_demos},{tmp_path / 'empty'}]", f"--dataset.root={tmp_path / 'b'}")
    assert no_episodes.returncode == 2 and "holds no episodes" in no_episodes.stderr
