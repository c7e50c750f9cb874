"""The console scripts as a user runs them: igen-collect (incl. resume after a kill) and
LeRobot's own lerobot-train / lerobot-eval on our env plugin and dataset."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from igen_lerobot.datasets.reader import load_episodes

BIN = Path(sys.executable).parent


def run(cmd, **kwargs):
    env = {**os.environ, "MUJOCO_GL": "egl", "HF_HUB_OFFLINE": "1"}
    return subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=300, **kwargs)


def collect_cmd(root, n, seed=5, mode="interventions"):
    return [
        str(BIN / "igen-collect"),
        "--env.type=block_grasp",
        f"--mode={mode}",
        f"--num_episodes={n}",
        f"--seed={seed}",
        "--dataset.repo_id=local/cli",
        f"--dataset.root={root}",
    ]


def lerobot_train_cmd(tmp_path, policy_type, steps, *extra):
    """LeRobot's own lerobot-train on the demos recorded under tmp_path/demos, a few CPU steps."""
    return [
        str(BIN / "lerobot-train"),
        f"--policy.type={policy_type}",
        *extra,
        "--dataset.repo_id=local/cli",
        f"--dataset.root={tmp_path / 'demos'}",
        f"--steps={steps}",
        "--batch_size=2",
        "--policy.device=cpu",
        f"--output_dir={tmp_path / 'train'}",
        "--policy.push_to_hub=false",
        f"--save_freq={steps}",
        "--num_workers=0",
        "--wandb.enable=false",
    ]


@pytest.fixture(scope="module")
def spec():
    from lerobot_env_igen.block_grasp.spec import SPEC

    return SPEC


def test_collect_resumes_after_kill_to_the_same_dataset(tmp_path, spec):
    reference = run(collect_cmd(tmp_path / "ref", 3))
    assert reference.returncode == 0, reference.stderr[-3000:]

    env = {**os.environ, "MUJOCO_GL": "egl", "HF_HUB_OFFLINE": "1"}
    proc = subprocess.Popen(
        collect_cmd(tmp_path / "resumed", 3), env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    spool = tmp_path / "resumed.partial" / "attempts"
    deadline = time.time() + 300
    while time.time() < deadline and not list(spool.glob("attempt_*.npz")) and proc.poll() is None:
        time.sleep(0.05)
    proc.send_signal(signal.SIGKILL)  # a killed process: no cleanup handlers run
    proc.wait()
    assert not (tmp_path / "resumed").exists(), "no dataset may appear before the run finished"
    kept_before = len(list(spool.glob("attempt_*.npz")))
    assert 1 <= kept_before < 3, "the kill must land mid-run"

    resumed = run(collect_cmd(tmp_path / "resumed", 3))
    assert resumed.returncode == 0, resumed.stderr[-3000:]
    assert "resuming" in resumed.stderr
    a, b = load_episodes(tmp_path / "ref", spec), load_episodes(tmp_path / "resumed", spec)
    assert [e.seed for e in a] == [e.seed for e in b]
    for x, y in zip(a, b, strict=True):
        np.testing.assert_array_equal(x.action, y.action)
        np.testing.assert_array_equal(x.is_intervention, y.is_intervention)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--env.type=block_grasp", "--mode=demo"], "--mode must be one of ('demos', 'interventions')"),
        (["--env.type=block_grasp", "--operator=teleop"], "--teleop.type=keyboard_ee"),
        (["--env.type=block_grasp", "--num_episodes=0"], "--num_episodes must be >= 1"),
        ([], "--env.type is required"),
    ],
)
def test_collect_config_rejects_bad_flags_with_the_fix(args, message):
    import re

    import draccus

    from igen_lerobot.collection.config_collect import CollectConfig
    from igen_lerobot.core.env_config import known_tasks

    known_tasks()  # plugin discovery, as the console script does before parsing
    from igen_lerobot.core.exceptions import ConfigError
    from igen_lerobot.scripts.cli import find_igen_error

    # draccus wraps our ConfigError in its own parsing error; the CLI digs it out (see cli.py)
    with pytest.raises(Exception) as caught:  # noqa: PT011
        draccus.parse(CollectConfig, args=args)
    error = find_igen_error(caught.value)
    assert isinstance(error, ConfigError) and re.search(re.escape(message), str(error))


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--mode=igen", "--mimicgen.replay.target_noise=0.002"], "--mimicgen.* flags apply to --mode=mimicgen"),
        (["--mode=igen_no_policy", "--mimicgen.selection=random"], "--mode=igen_no_policy reads --igen.*"),
        (["--mode=mimicgen", "--igen.replay.target_noise=0.002"], "--mode=mimicgen reads --mimicgen.*"),
    ],
)
def test_generate_refuses_the_other_modes_flags_instead_of_dropping_them(args, message):
    import re

    import draccus

    from igen_lerobot.core.env_config import known_tasks
    from igen_lerobot.core.exceptions import ConfigError
    from igen_lerobot.generation.config_generate import GenerateConfig
    from igen_lerobot.scripts.cli import find_igen_error

    known_tasks()
    common = ["--env.type=block_grasp", "--source.root=outputs/x"]
    with pytest.raises(Exception) as caught:  # noqa: PT011
        draccus.parse(GenerateConfig, args=[*common, *args])
    error = find_igen_error(caught.value)
    assert isinstance(error, ConfigError) and re.search(re.escape(message), str(error))
    # the flag is taken in its own mode
    own = "--mode=mimicgen" if "mimicgen" in args[1] else "--mode=igen"
    cfg = draccus.parse(GenerateConfig, args=[*common, own, args[1]])
    assert cfg.mode == own.split("=")[1]


def test_collect_cli_reports_bad_flags(tmp_path):
    result = run(collect_cmd(tmp_path / "x", 1, mode="demo"))
    assert result.returncode == 2
    assert "igen-collect: error: --mode must be one of ('demos', 'interventions')" in result.stderr
    assert "Traceback" not in result.stderr
    assert not (tmp_path / "x").exists() and not (tmp_path / "x.partial").exists()


def test_lerobot_train_and_eval_run_on_our_dataset_and_env(tmp_path):
    demos = run(collect_cmd(tmp_path / "demos", 2, mode="demos"))
    assert demos.returncode == 0, demos.stderr[-3000:]
    train = run(lerobot_train_cmd(tmp_path, "act", steps=2))
    assert train.returncode == 0, train.stderr[-3000:]
    checkpoint = tmp_path / "train/checkpoints/last/pretrained_model"
    evaluation = run(
        [
            str(BIN / "lerobot-eval"),
            f"--policy.path={checkpoint}",
            "--env.type=block_grasp",
            "--env.episode_length=10",
            "--eval.n_episodes=1",
            "--eval.batch_size=1",
            "--policy.device=cpu",
            f"--output_dir={tmp_path / 'eval'}",
        ]
    )
    assert evaluation.returncode == 0, evaluation.stderr[-3000:]
    import json

    info = json.loads((tmp_path / "eval/eval_info.json").read_text())
    assert info["overall"]["n_episodes"] == 1
    assert (tmp_path / "eval/videos/block_grasp_0/eval_episode_0.mp4").stat().st_size > 1000


def test_lerobot_diffusion_trains_on_environment_state_and_runs_in_igen_eval(tmp_path):
    """LeRobot's diffusion policy (state + environment_state, no images) on our data and env."""
    demos = run(collect_cmd(tmp_path / "demos", 2, mode="demos"))
    assert demos.returncode == 0, demos.stderr[-3000:]
    # a small U-Net and few denoising steps: plumbing, not quality
    train = run(
        lerobot_train_cmd(tmp_path, "diffusion", 1, "--policy.down_dims=[32,64]", "--policy.num_inference_steps=2")
    )
    assert train.returncode == 0, train.stderr[-3000:]
    out = tmp_path / "eval.json"
    evaluation = run(
        [
            str(BIN / "igen-eval"),
            "--env.type=block_grasp",
            "--env.episode_length=12",
            f"--policy.path={tmp_path / 'train/checkpoints/last/pretrained_model'}",
            "--n_trials=1",
            f"--output={out}",
        ]
    )
    assert evaluation.returncode == 0, evaluation.stderr[-3000:]
    import json

    report = json.loads(out.read_text())
    assert report["best"]["trials"] == 1 and report["best"]["mean_steps"] <= 12
