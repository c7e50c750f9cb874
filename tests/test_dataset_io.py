"""Datasets round-trip through LeRobot's own LeRobotDataset; bad inputs name their field."""

import dataclasses
import json

import numpy as np
import pandas as pd
import pytest
from lerobot.datasets.lerobot_dataset import LeRobotDataset

from igen_lerobot.core.episode import Episode, EpisodeKind
from igen_lerobot.core.exceptions import ConfigError, DatasetSchemaError, TaskMismatchError
from igen_lerobot.core.task import FrameSource
from igen_lerobot.datasets.reader import load_episodes, read_igen_meta
from igen_lerobot.datasets.schema import FRAME_SOURCE, IS_INTERVENTION, SIM_STATE, dataset_features
from igen_lerobot.datasets.writer import DatasetBuilder


def synthetic_episode(spec, rng, length=30, kind=EpisodeKind.INTERVENTION, seed=0):
    takeover = length // 2
    source = np.where(np.arange(length) < takeover, FrameSource.POLICY, FrameSource.OPERATOR)
    return Episode(
        task=spec.name,
        kind=kind,
        seed=seed,
        corruption=rng.uniform(-0.05, 0.05, 3),
        state=rng.normal(size=(length, len(spec.state_names))),
        env_state=rng.normal(size=(length, len(spec.env_state_names))),
        action=rng.normal(size=(length, len(spec.action_names))),
        is_intervention=source == FrameSource.OPERATOR,
        source=source.astype(np.int64),
        subtask=np.zeros(length, dtype=np.int64),
        true_object_pose=rng.normal(size=(length, len(spec.object_pose_names))),
        success=True,
    )


@pytest.fixture(scope="module")
def spec():
    from lerobot_env_igen.block_grasp.spec import SPEC

    return SPEC


def build(tmp_path, spec, episodes, name="ds", **kwargs):
    builder = DatasetBuilder(tmp_path / name, f"local/{name}", spec)
    for i, ep in enumerate(episodes):
        builder.spool.keep(i, ep)
    return builder.finalize(None, metadata={"created_by": "test"}, **kwargs)


def test_round_trip_through_lerobot(tmp_path, spec):
    rng = np.random.default_rng(0)
    episodes = [synthetic_episode(spec, rng, length=20 + 5 * i, seed=i) for i in range(3)]
    summary = build(tmp_path, spec, episodes)
    assert summary.episodes == 3 and summary.frames == sum(e.length for e in episodes)

    ds = LeRobotDataset("local/ds", root=tmp_path / "ds")  # LeRobot's own loader
    assert ds.num_episodes == 3 and ds.num_frames == summary.frames
    assert ds.meta.features[IS_INTERVENTION]["dtype"] == "bool"
    item = ds[episodes[0].length + 2]  # third frame of episode 1
    np.testing.assert_allclose(item["observation.state"].numpy(), episodes[1].state[2], rtol=1e-6)
    np.testing.assert_allclose(item["action"].numpy(), episodes[1].action[2], rtol=1e-6)
    assert item["task"] == spec.instruction
    assert bool(item[IS_INTERVENTION]) == bool(episodes[1].is_intervention[2])

    loaded = load_episodes(tmp_path / "ds", spec)
    for a, b in zip(loaded, episodes, strict=True):
        for field in ("state", "env_state", "action", "true_object_pose", "corruption"):
            np.testing.assert_allclose(getattr(a, field), getattr(b, field), rtol=1e-6, atol=1e-7)
        np.testing.assert_array_equal(a.is_intervention, b.is_intervention)
        np.testing.assert_array_equal(a.source, b.source)
        assert (a.seed, a.kind, a.success) == (b.seed, b.kind, b.success)
    assert read_igen_meta(tmp_path / "ds").meta["episode_kinds"] == {"intervention": 3}


def test_fast_write_is_identical_to_lerobots_own_path(tmp_path, spec):
    """Skipping the image-embedding pass and datasets' fingerprint hashing changes no byte written."""
    from igen_lerobot.datasets.writer import task_sim_state_layout

    rng = np.random.default_rng(1)
    episodes = [synthetic_episode(spec, rng, seed=i) for i in range(2)]
    for episode in episodes:  # with a simulator-state column, as every simulated task writes
        episode.sim_state = rng.normal(size=(episode.length, task_sim_state_layout(spec)["size"]))
    build(tmp_path, spec, episodes, name="fast", fast_write=True)
    build(tmp_path, spec, episodes, name="slow", fast_write=False)
    fast = pd.read_parquet(tmp_path / "fast" / "data" / "chunk-000" / "file-000.parquet")
    slow = pd.read_parquet(tmp_path / "slow" / "data" / "chunk-000" / "file-000.parquet")
    pd.testing.assert_frame_equal(fast, slow)
    assert json.loads((tmp_path / "fast/meta/stats.json").read_text()) == json.loads(
        (tmp_path / "slow/meta/stats.json").read_text()
    )


def test_interrupted_build_never_looks_complete_and_resumes(tmp_path, spec, monkeypatch):
    rng = np.random.default_rng(2)
    episodes = [synthetic_episode(spec, rng, seed=i) for i in range(3)]
    builder = DatasetBuilder(tmp_path / "ds", "local/ds", spec)
    for i, ep in enumerate(episodes):
        builder.spool.keep(i, ep)

    calls = {"n": 0}
    original = LeRobotDataset.save_episode

    def dying_save_episode(self, *args, **kwargs):
        calls["n"] += 1
        if calls["n"] == 2:
            raise KeyboardInterrupt  # Ctrl-C in the middle of writing
        return original(self, *args, **kwargs)

    monkeypatch.setattr(LeRobotDataset, "save_episode", dying_save_episode)
    with pytest.raises(KeyboardInterrupt):
        builder.finalize(None, metadata={})
    monkeypatch.undo()
    assert not (tmp_path / "ds").exists(), "a half-written dataset must not appear at root"
    assert (tmp_path / "ds.partial" / "attempts").exists()

    resumed = DatasetBuilder(tmp_path / "ds", "local/ds", spec)
    assert resumed.resuming and resumed.spool.kept_attempts() == [0, 1, 2]
    resumed.finalize(None, metadata={})
    assert len(load_episodes(tmp_path / "ds", spec)) == 3
    assert not (tmp_path / "ds.partial").exists()


def test_existing_dataset_is_not_overwritten_by_default(tmp_path, spec):
    build(tmp_path, spec, [synthetic_episode(spec, np.random.default_rng(3))])
    with pytest.raises(ConfigError, match="overwrite"):
        DatasetBuilder(tmp_path / "ds", "local/ds", spec)


def test_wrong_shapes_name_the_field(spec):
    ep = synthetic_episode(spec, np.random.default_rng(4))
    bad = dataclasses.replace(ep, state=ep.state[:, :5])
    with pytest.raises(DatasetSchemaError, match=r"episode\.state has shape"):
        bad.validate(spec)
    bad = dataclasses.replace(ep, is_intervention=ep.is_intervention[:-1])
    with pytest.raises(DatasetSchemaError, match="is_intervention"):
        bad.validate(spec)
    bad = dataclasses.replace(ep, task="nut_insertion")
    with pytest.raises(DatasetSchemaError, match="task"):
        bad.validate(spec)


def test_dataset_of_another_task_is_rejected(tmp_path, spec):
    build(tmp_path, spec, [synthetic_episode(spec, np.random.default_rng(5))])
    other = dataclasses.replace(spec, name="nut_insertion")
    with pytest.raises(TaskMismatchError, match="holds task 'block_grasp'"):
        load_episodes(tmp_path / "ds", other)


def test_plain_lerobot_dataset_without_flags_is_rejected(tmp_path, spec):
    features = {k: v for k, v in dataset_features(spec).items() if not k.startswith("complementary_info")}
    ds = LeRobotDataset.create("local/plain", fps=20, features=features, root=tmp_path / "plain", use_videos=False)
    for _ in range(3):
        ds.add_frame({k: np.zeros(v["shape"], dtype=v["dtype"]) for k, v in features.items()} | {"task": "x"})
    ds.save_episode()
    ds.finalize()
    with pytest.raises(DatasetSchemaError, match="igen metadata"):
        load_episodes(tmp_path / "plain", spec)
    # even with the metadata file, the missing flag column is named
    (tmp_path / "plain/meta/igen.json").write_text(json.dumps({"task": spec.name}))
    with pytest.raises(DatasetSchemaError, match="complementary_info"):
        load_episodes(tmp_path / "plain", spec)


def test_frame_source_names_in_features(spec):
    assert dataset_features(spec)[FRAME_SOURCE]["names"] == ["policy", "operator", "generated", "interpolation"]


def test_a_block_grasp_dataset_written_before_the_core_held_several_tasks_still_works(tmp_path, block_grasp_env):
    """tests/data/block_grasp_written_before_tasks: 2 interventions recorded by the release before the
    general core (no reveal mode in its meta/igen.json). It loads, seeds generation and merges."""
    from pathlib import Path

    from igen_lerobot.core.belief import Reveal
    from igen_lerobot.datasets.merge import merge_datasets
    from igen_lerobot.datasets.reader import dataset_spec
    from igen_lerobot.generation.intervengen import IntervenGenConfig, MistakeSource, generate_intervention
    from igen_lerobot.generation.sources import parse_interventions

    old = Path(__file__).parent / "data" / "block_grasp_written_before_tasks"
    assert "reveal" not in read_igen_meta(old).meta
    spec = dataset_spec(old)
    assert spec.name == "block_grasp" and spec.reveal is Reveal.FULL
    episodes = load_episodes(old, spec)
    assert len(episodes) == 2 and all(ep.success and ep.is_intervention.any() for ep in episodes)
    env = block_grasp_env
    library = parse_interventions(episodes, spec, env.target_pose_from_action, env.gripper_command)
    attempts = [
        generate_intervention(env, None, library, IntervenGenConfig(), seed, 320, MistakeSource.REPLAY)
        for seed in range(6)
    ]
    kept = [a.episode for a in attempts if a.kept]
    assert kept, [a.reason for a in attempts]
    new = DatasetBuilder(tmp_path / "new", "local/new", spec)
    for i, ep in enumerate(kept):
        new.spool.keep(i, ep)
    new.finalize(None, {"created_by": "test"})
    # the old dataset predates LeRobot's RL columns: the merge rewrites it with them, the input untouched
    merged = merge_datasets([old, tmp_path / "new"], tmp_path / "merged", "local/merged", spec)
    dataset = LeRobotDataset("local/merged", root=merged)
    assert dataset.meta.total_episodes == 2 + len(kept)
    rewards = np.array(dataset.hf_dataset["next.reward"]).reshape(-1)
    assert rewards.sum() == 2 + len(kept)  # one per successful episode, the old ones included
    assert "next.reward" not in json.loads((old / "meta" / "info.json").read_text())["features"]
    # the new part carries simulator states, the old one cannot: the merge keeps none (and says so)
    assert SIM_STATE in LeRobotDataset("local/new", root=tmp_path / "new").meta.features
    assert SIM_STATE not in dataset.meta.features and "sim_state_layout" not in read_igen_meta(merged).meta


def test_lerobots_rl_replay_buffer_loads_our_dataset_with_the_intervention_flags(tmp_path, spec):
    """next.reward / next.done follow LeRobot's RL conventions: LeRobot's own ReplayBuffer loads us."""
    import torch
    from lerobot.rl.buffer import ReplayBuffer

    from igen_lerobot.core.task import OBS_ENV_STATE, OBS_STATE
    from igen_lerobot.datasets.schema import DONE, REWARD

    rng = np.random.default_rng(0)
    episodes = [synthetic_episode(spec, rng, length=12, seed=1), synthetic_episode(spec, rng, length=9, seed=2)]
    episodes[1].success = False
    builder = DatasetBuilder(tmp_path / "rl", "local/rl", spec)
    for i, ep in enumerate(episodes):
        builder.spool.keep(i, ep)
    builder.finalize(None, {"created_by": "test"})
    dataset = LeRobotDataset("local/rl", root=tmp_path / "rl")
    assert dataset.meta.features[REWARD]["dtype"] == "float32" and dataset.meta.features[DONE]["dtype"] == "bool"
    buffer = ReplayBuffer.from_lerobot_dataset(
        dataset, device="cpu", state_keys=[OBS_STATE, OBS_ENV_STATE], use_drq=False
    )
    assert buffer.size == 21
    np.testing.assert_array_equal(buffer.rewards[:21].numpy(), np.eye(21)[11])  # 1.0 on the success frame only
    dones = np.zeros(21, dtype=bool)
    dones[[11, 20]] = True  # the last frame of each episode, failed or not
    np.testing.assert_array_equal(buffer.dones[:21].numpy(), dones)
    flags = np.concatenate([ep.is_intervention for ep in episodes])
    np.testing.assert_array_equal(buffer.complementary_info["is_intervention"][:21].reshape(-1).numpy(), flags)
    sampled = buffer.sample(64)["complementary_info"]["is_intervention"]  # the buffer stores flags as 0/1 floats
    assert len(sampled) > 0 and set(torch.unique(sampled).tolist()) <= {0.0, 1.0}
