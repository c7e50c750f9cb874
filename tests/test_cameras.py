"""Camera streams: igen-render from recorded simulator states, the env's image observations, and a
vision policy (LeRobot's ACT) trained on a rendered dataset and evaluated in the env.

Tolerances: decoded video frames are AV1 (LeRobot's default encoding), so they match the rendered
pixels to a mean absolute error of 6/255; everything before encoding is compared exactly.
"""

import dataclasses
import hashlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from lerobot.datasets.lerobot_dataset import LeRobotDataset

from igen_lerobot.collection.record import record_demo
from igen_lerobot.core.cameras import CameraConfig, image_key, render_images
from igen_lerobot.core.error_models import NoNoise
from igen_lerobot.core.exceptions import ConfigError, DatasetSchemaError
from igen_lerobot.core.seeding import episode_seed
from igen_lerobot.datasets.reader import load_episodes
from igen_lerobot.datasets.render import render_dataset
from igen_lerobot.datasets.writer import DatasetBuilder

BIN = Path(sys.executable).parent
ENV = {**os.environ, "MUJOCO_GL": "egl", "HF_HUB_OFFLINE": "1"}
SIZE = 64


def _demos(config, root: Path, n: int) -> Path:
    config = dataclasses.replace(config, corruption=NoNoise())
    env, operator = config.make_task_env(), config.make_scripted_operator()
    builder = DatasetBuilder(root, f"local/{root.name}", config.task_spec)
    for i in range(n):
        builder.spool.keep(i, record_demo(env, operator, episode_seed(11, i), config.episode_length))
    builder.finalize(None, {"created_by": "test"})
    env.close()
    return root


@pytest.fixture(scope="module")
def demos(tmp_path_factory, block_grasp_config):
    """Three Block Grasp demonstrations with their simulator states (state only, as generated)."""
    return _demos(block_grasp_config, tmp_path_factory.mktemp("cams") / "demos", 3)


@pytest.fixture(scope="module")
def rendered(demos):
    out = demos.with_name("demos_rgb")
    render_dataset(demos, out, "local/demos_rgb", CameraConfig(["agentview", "wrist"], SIZE), episodes_per_chunk=2)
    return out


def _digest(root: Path) -> dict[str, str]:
    files = (p for p in root.rglob("*") if p.is_file())
    return {str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest() for p in files}


def test_rendered_frames_are_the_env_observation_of_the_recorded_state(demos, rendered, block_grasp_config):
    source, images = LeRobotDataset("local/d", root=demos), LeRobotDataset("local/r", root=rendered)
    assert images.meta.total_episodes == 3 and images.meta.total_frames == source.meta.total_frames
    for camera in ("agentview", "wrist"):
        feature = images.meta.features[image_key(camera)]
        assert feature["dtype"] == "video" and tuple(feature["shape"]) == (SIZE, SIZE, 3)
    meta = json.loads((rendered / "meta" / "igen.json").read_text())
    assert meta["cameras"] == {"agentview": {"size": SIZE}, "wrist": {"size": SIZE}}
    assert meta["task"] == "block_grasp" and meta["sim_state_layout"]["size"] > 0
    # every non-image column is carried over unchanged
    for key in ("action", "observation.state", "complementary_info.is_intervention", "complementary_info.sim_state"):
        np.testing.assert_array_equal(np.asarray(images.hf_dataset[key]), np.asarray(source.hf_dataset[key]))

    # the env path: lerobot-eval's observation at a recorded state, through the gym env
    import gymnasium as gym

    config = dataclasses.replace(block_grasp_config, obs_type="pixels_state", image_size=SIZE)
    gym_env = gym.make(config.gym_id, disable_env_checker=True, **config.gym_kwargs)
    gym_env.reset(seed=0)
    task_env = gym_env.unwrapped.task_env
    episode = load_episodes(demos, config.task_spec, episodes=[1])[0]
    first = int(np.flatnonzero(np.asarray(images.hf_dataset["episode_index"]) == 1)[0])
    for t in (0, episode.length // 2):
        task_env.restore_sim_state(episode.sim_state[t])
        observed = gym_env.unwrapped._to_gym(task_env.observe())["pixels"]
        direct = render_images(task_env, ["agentview", "wrist"], SIZE)
        for camera in ("agentview", "wrist"):
            assert gym_env.observation_space["pixels"][camera].contains(observed[camera])
            np.testing.assert_array_equal(observed[camera], direct[camera])  # one pipeline, exactly
            decoded = (images[first + t][image_key(camera)].numpy().transpose(1, 2, 0) * 255).astype(np.float32)
            assert np.abs(decoded - direct[camera]).mean() < 6, camera  # AV1 is lossy
    gym_env.close()

    # the images are not blank: the red cube is in the first agentview frame, frames differ over time
    frame0 = images[0][image_key("agentview")].numpy()
    red = (frame0[0] > 0.5) & (frame0[1] < 0.25) & (frame0[2] < 0.25)
    assert red.sum() >= 4, "the cube is not visible in the first agentview frame"
    last = images[images.meta.episodes["length"][0] - 1][image_key("wrist")].numpy()
    assert np.abs(last - images[0][image_key("wrist")].numpy()).mean() > 0.02


def test_render_refuses_what_it_cannot_render_and_leaves_nothing(demos, tmp_path):
    before = _digest(demos)
    unknown = r"^--cameras: task 'block_grasp' has no camera 'top'; its cameras: \['agentview'"
    with pytest.raises(ConfigError, match=unknown):
        render_dataset(demos, tmp_path / "a", "local/a", CameraConfig(["top"], SIZE))
    with pytest.raises(ConfigError, match=r"^--size=4 px is out of range"):
        render_dataset(demos, tmp_path / "a", "local/a", CameraConfig(["wrist"], 4))
    with pytest.raises(ConfigError, match="the input is never modified"):
        render_dataset(demos, demos, "local/a", CameraConfig(["wrist"], SIZE))
    # a dataset written before simulator states were recorded
    old = Path(__file__).parent / "data" / "block_grasp_written_before_tasks"
    with pytest.raises(DatasetSchemaError, match="carries no simulator states .* cannot be rendered"):
        render_dataset(old, tmp_path / "b", "local/b", CameraConfig(["wrist"], SIZE))
    # states recorded by another version of the task's scene
    import shutil

    other = tmp_path / "other_version"
    shutil.copytree(demos, other)
    meta = json.loads((other / "meta" / "igen.json").read_text())
    meta["sim_state_layout"]["model"]["nbody"] += 1
    (other / "meta" / "igen.json").write_text(json.dumps(meta))
    with pytest.raises(DatasetSchemaError, match="another layout of task 'block_grasp'"):
        render_dataset(other, tmp_path / "c", "local/c", CameraConfig(["wrist"], SIZE))
    assert not any((tmp_path / n).exists() for n in ("a", "b", "c", "a.partial", "b.partial", "c.partial"))
    assert _digest(demos) == before


def test_a_killed_render_resumes_without_ever_showing_a_half_written_dataset(demos, tmp_path):
    out = tmp_path / "out"
    command = [
        str(BIN / "igen-render"),
        f"--dataset.root={demos}",
        "--cameras=[wrist]",
        f"--size={SIZE}",
        f"--output.root={out}",
        "--episodes_per_chunk=1",
    ]
    proc = subprocess.Popen(command, env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    chunks = out.with_name("out.partial") / "chunks"
    deadline = time.time() + 300
    while time.time() < deadline and not (chunks / "chunk_00000").exists() and proc.poll() is None:
        time.sleep(0.05)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert not out.exists(), "no dataset may appear before the render finished"
    done = sorted(p.name for p in chunks.iterdir() if not p.name.endswith(".building"))
    assert 1 <= len(done) < 3, f"the kill must land mid-run: {done}"
    resumed = subprocess.run(command, env=ENV, capture_output=True, text=True, timeout=300)
    assert resumed.returncode == 0, resumed.stderr[-3000:]
    assert f"{len(done)} of 3 chunks already rendered" in resumed.stderr
    assert not out.with_name("out.partial").exists()
    dataset = LeRobotDataset("local/out", root=out)
    source = LeRobotDataset("local/d", root=demos)
    assert dataset.meta.total_episodes == 3 and dataset.meta.total_frames == source.meta.total_frames
    np.testing.assert_array_equal(np.asarray(dataset.hf_dataset["action"]), np.asarray(source.hf_dataset["action"]))
    bad = subprocess.run([*command[:-3], "--cameras=[top]"], env=ENV, capture_output=True, text=True, timeout=300)
    assert bad.returncode == 2 and "--cameras: task 'block_grasp' has no camera 'top'" in bad.stderr
    assert "Traceback" not in bad.stderr


def test_act_trains_on_a_rendered_dataset_and_lerobot_eval_runs_it_on_the_env_cameras(rendered, tmp_path):
    """LeRobot's ACT with images + state: a few CPU steps (plumbing, not quality), then lerobot-eval."""
    train = subprocess.run(
        [
            str(BIN / "lerobot-train"),
            "--policy.type=act",
            "--policy.pretrained_backbone_weights=null",  # nothing is downloaded at run time
            "--policy.dim_model=64",
            "--policy.chunk_size=10",
            "--policy.n_action_steps=10",
            "--dataset.repo_id=local/demos_rgb",
            f"--dataset.root={rendered}",
            "--steps=2",
            "--batch_size=2",
            "--policy.device=cpu",
            f"--output_dir={tmp_path / 'train'}",
            "--policy.push_to_hub=false",
            "--save_freq=2",
            "--num_workers=0",
            "--wandb.enable=false",
        ],
        env=ENV,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert train.returncode == 0, train.stderr[-3000:]
    checkpoint = tmp_path / "train/checkpoints/last/pretrained_model"
    policy_config = json.loads((checkpoint / "config.json").read_text())
    assert {image_key("agentview"), image_key("wrist")} <= set(policy_config["input_features"])
    evaluation = subprocess.run(
        [
            str(BIN / "lerobot-eval"),
            f"--policy.path={checkpoint}",
            "--env.type=block_grasp",
            "--env.obs_type=pixels_state",
            f"--env.image_size={SIZE}",
            "--env.episode_length=5",
            "--eval.n_episodes=1",
            "--eval.batch_size=1",
            "--policy.device=cpu",
            f"--output_dir={tmp_path / 'eval'}",
        ],
        env=ENV,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert evaluation.returncode == 0, evaluation.stderr[-3000:]
    info = json.loads((tmp_path / "eval/eval_info.json").read_text())
    assert info["overall"]["n_episodes"] == 1

    # igen-eval: the same env flags; without the cameras it says which flags the checkpoint needs
    igen_eval = [
        str(BIN / "igen-eval"),
        "--env.type=block_grasp",
        f"--policy.path={checkpoint}",
        "--env.episode_length=5",
        "--n_trials=1",
    ]
    out = tmp_path / "igen_eval.json"
    ours = subprocess.run(
        [*igen_eval, "--env.obs_type=pixels_state", f"--env.image_size={SIZE}", f"--output={out}"],
        env=ENV,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert ours.returncode == 0, ours.stderr[-3000:]
    assert json.loads(out.read_text())["best"]["trials"] == 1
    state_only = subprocess.run(igen_eval, env=ENV, capture_output=True, text=True, timeout=300)
    assert state_only.returncode == 2, state_only.stderr[-3000:]
    fix = f"--env.obs_type=pixels_state --env.cameras='[agentview,wrist]' --env.image_size={SIZE}"
    assert fix in state_only.stderr


def test_igen_collect_renders_cameras_into_the_dataset_it_writes(tmp_path, demos):
    root = tmp_path / "collected"
    common = ["--env.type=block_grasp", "--mode=demos", "--num_episodes=1", f"--dataset.root={root}"]
    headless_by_default = {k: v for k, v in ENV.items() if k != "MUJOCO_GL"}
    result = subprocess.run(
        [str(BIN / "igen-collect"), *common, "--render.cameras=[wrist]", "--render.size=48"],
        env=headless_by_default,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 0, "\n".join(line for line in result.stderr.splitlines() if "Svt" not in line)[-3000:]
    dataset = LeRobotDataset("local/collected", root=root)
    assert tuple(dataset.meta.features[image_key("wrist")]["shape"]) == (48, 48, 3)
    assert "complementary_info.sim_state" in dataset.meta.features  # still renderable with other cameras
    assert dataset[0][image_key("wrist")].shape == (3, 48, 48)
    meta = json.loads((root / "meta" / "igen.json").read_text())
    assert meta["created_by"] == "igen-collect" and meta["cameras"] == {"wrist": {"size": 48}}
    assert not root.with_name("collected.partial").exists()
    # a camera the task lacks stops both commands before any work, naming the task's cameras
    for command, args in (
        ("igen-collect", [*common[:-1], f"--dataset.root={tmp_path / 'x'}"]),
        ("igen-generate", ["--task=block_grasp", f"--source.root={demos}", f"--dataset.root={tmp_path / 'x'}"]),
    ):
        bad = subprocess.run(
            [str(BIN / command), *args, "--render.cameras=[top]"], env=ENV, capture_output=True, text=True, timeout=300
        )
        flag = "--render.cameras: task 'block_grasp' has no camera 'top'; its cameras:"
        assert bad.returncode == 2 and flag in bad.stderr, bad.stderr[-2000:]
        assert not (tmp_path / "x").exists() and not (tmp_path / "x.partial").exists()


def test_igen_viz_shows_the_camera_streams_next_to_the_path(rendered, tmp_path):
    """Read back with Rerun's own reader: one JPEG per frame and camera, matching the dataset's frame."""
    import io

    from PIL import Image
    from test_viz import column, read_rrd

    from igen_lerobot.viz.replay import replay_dataset
    from igen_lerobot.viz.rerun_log import RerunConfig

    out = tmp_path / "rendered.rrd"
    result = replay_dataset(rendered, RerunConfig(mode="save", path=str(out)), episodes=[0])
    assert result["cameras"] == ["agentview", "wrist"]
    chunks = read_rrd(out)
    assert "/episodes/0/path" in chunks
    dataset = LeRobotDataset("local/r", root=rendered, episodes=[0])
    for camera in ("agentview", "wrist"):
        blobs = column(chunks[f"/episodes/0/cameras/{camera}"], "EncodedImage:blob")
        assert len(blobs) == len(dataset)
        shown = np.asarray(Image.open(io.BytesIO(bytes(blobs[0][0])))).astype(np.float32)
        stored = dataset[0][image_key(camera)].numpy().transpose(1, 2, 0) * 255
        assert shown.shape == (SIZE, SIZE, 3) and np.abs(shown - stored).mean() < 4  # JPEG at quality 90


def test_the_dataset_card_lists_the_cameras(rendered):
    from igen_lerobot.datasets.card import card_fields
    from igen_lerobot.datasets.reader import dataset_spec, read_igen_meta

    info = json.loads((rendered / "meta" / "info.json").read_text())
    body = card_fields(rendered, dataset_spec(rendered), info, read_igen_meta(rendered).meta)["dataset_description"]
    assert (
        f"**Cameras** (2): `observation.images.agentview` ({SIZE}x{SIZE} px, video), "
        f"`observation.images.wrist` ({SIZE}x{SIZE} px, video), rendered from the recorded simulator states"
    ) in body


def test_two_render_workers_write_what_one_writes(demos, rendered, tmp_path):
    """Chunks rendered by two processes and joined in order give the single-process dataset."""
    out = tmp_path / "two"
    render_dataset(demos, out, "local/two", CameraConfig(["agentview", "wrist"], SIZE), num_workers=2)
    one, two = LeRobotDataset("local/r", root=rendered), LeRobotDataset("local/two", root=out)
    assert two.meta.total_episodes == one.meta.total_episodes == 3
    np.testing.assert_array_equal(np.asarray(two.hf_dataset["action"]), np.asarray(one.hf_dataset["action"]))
    for i in (0, len(one) // 2, len(one) - 1):
        for camera in ("agentview", "wrist"):
            a, b = one[i][image_key(camera)].numpy(), two[i][image_key(camera)].numpy()
            assert np.abs(a - b).max() < 1e-6, (i, camera)  # same pixels, same encoder settings


def test_the_env_config_names_its_own_flags_for_bad_cameras(block_grasp_config):
    config_class = type(block_grasp_config)
    with pytest.raises(ConfigError, match=r"^--env.cameras: task 'block_grasp' has no camera 'top'; its cameras"):
        config_class(obs_type="pixels_state", cameras=["top"])
    with pytest.raises(ConfigError, match=r"^--env.image_size=4 px is out of range"):
        config_class(obs_type="pixels_state", image_size=4)
    with pytest.raises(ConfigError, match=r"env.obs_type='pixels' is not one of \['state', 'pixels_state'\]"):
        config_class(obs_type="pixels")
