import os

os.environ.setdefault("MUJOCO_GL", "egl")
os.environ.setdefault("HF_HUB_OFFLINE", "1")  # tests never reach the Hub

import shutil  # noqa: E402
import subprocess  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

# the numpy-only fake task registers itself as an igen task, so the per-task tests cover it too
import fake_task  # noqa: E402, F401
import pytest  # noqa: E402
from hypothesis import settings  # noqa: E402

# Property tests check maths, not speed: hypothesis's 200 ms per-example deadline failed a fresh
# clone's first examples (a cold import took 259-589 ms on a busy 2-core machine)
settings.register_profile("igen", deadline=None)
settings.load_profile("igen")


@pytest.fixture()
def x_display():
    """A real X server (Xvfb) on a free display number, for tests that type on LeRobot's keyboard teleop."""
    if shutil.which("Xvfb") is None or shutil.which("xdotool") is None:
        pytest.fail("Xvfb and xdotool are missing: run scripts/setup.sh (it installs them)")
    number = next(n for n in range(90 + os.getpid() % 50, 200) if not Path(f"/tmp/.X11-unix/X{n}").exists())
    proc = subprocess.Popen(
        ["Xvfb", f":{number}", "-screen", "0", "640x480x24", "-nolisten", "tcp"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    socket = Path(f"/tmp/.X11-unix/X{number}")
    deadline = time.time() + 10
    while not socket.exists() and time.time() < deadline:
        time.sleep(0.05)
    assert socket.exists(), "Xvfb did not start"
    yield f":{number}"
    proc.terminate()
    proc.wait(timeout=10)


@pytest.fixture(scope="session")
def block_grasp_config():
    from igen_lerobot.core.env_config import task_config_class

    return task_config_class("block_grasp")()


@pytest.fixture(scope="session")
def block_grasp_env(block_grasp_config):
    env = block_grasp_config.make_task_env()
    yield env
    env.close()


def _record_sources(tmp_path_factory, config, mode, n, seed):
    import dataclasses

    from igen_lerobot.collection.record import record_demo, record_intervention
    from igen_lerobot.core.error_models import NoNoise
    from igen_lerobot.core.seeding import episode_seed
    from igen_lerobot.datasets.writer import DatasetBuilder

    if mode == "demos":
        config = dataclasses.replace(config, corruption=NoNoise())
    env = config.make_task_env()
    operator, policy = config.make_scripted_operator(), config.make_scripted_policy()
    root = tmp_path_factory.mktemp("sources") / f"block_grasp_{mode}"
    builder = DatasetBuilder(root, f"local/{root.name}", env.spec)
    kept, attempt = 0, 0
    while kept < n:
        s = episode_seed(seed, attempt)
        ep = (
            record_demo(env, operator, s, 200)
            if mode == "demos"
            else record_intervention(env, policy, operator, s, 200)
        )
        if ep.success and (mode == "demos" or ep.is_intervention.any()):
            builder.spool.keep(attempt, ep)
            kept += 1
        attempt += 1
    builder.finalize(n, metadata={"created_by": "test", "mode": mode})
    env.close()
    return root


@pytest.fixture(scope="session")
def source_demos(tmp_path_factory, block_grasp_config):
    """10 scripted-operator demonstrations, written as an igen dataset."""
    return _record_sources(tmp_path_factory, block_grasp_config, "demos", 10, seed=100)


@pytest.fixture(scope="session")
def source_interventions(tmp_path_factory, block_grasp_config):
    """10 human-gated (scripted operator) interventions, written as an igen dataset."""
    return _record_sources(tmp_path_factory, block_grasp_config, "interventions", 10, seed=200)


@pytest.fixture(scope="session")
def bc_rnn_checkpoint(source_demos, tmp_path_factory):
    """A BC-RNN checkpoint made by lerobot-train (3 steps: the plumbing, not a good policy)."""
    from igen_lerobot.training.config_train import TrainConfig
    from igen_lerobot.training.lerobot_train import lerobot_train

    cfg = TrainConfig(policy_type="bc_rnn", steps=3, batch_size=8, num_workers=0)
    return lerobot_train(cfg, source_demos, "local/block_grasp_demos", tmp_path_factory.mktemp("train") / "bc_rnn")


@pytest.fixture()
def tiny_table():
    """Runs ``igen-table`` on Block Grasp at the smallest sizes that still make every step.

    Called as ``tiny_table(output_dir, results_page, *more_flags, timeout=300)``; returns the finished
    process. The rows, seeds and checkpoints are the caller's flags.
    """
    import sys

    def run(out: Path, results: Path, *flags: str, timeout: float = 300) -> subprocess.CompletedProcess:
        command = [
            str(Path(sys.executable).parent / "igen-table"),
            "--source_episodes=2",
            "--base_demos=4",
            "--train.steps=2",
            "--train.batch_size=8",
            "--train.num_workers=0",
            "--n_trials=1",
            "--n_val_trials=1",
            "--workers=1",
            "--in_process=true",
            f"--output_dir={out}",
            f"--results={results}",
            *flags,
        ]
        return subprocess.run(command, capture_output=True, text=True, timeout=timeout, env=os.environ)

    return run


# Tests that run a robot or a person in wall-clock time (franky-sim's 1 kHz arm, LeRobot's
# record/replay/rollout loops, key presses on Xvfb): they run on their own, after the rest, so a
# parallel test never steals the cycles their timing depends on (see the Makefile's test target).
REALTIME_MODULES = {"test_franky_backend.py", "test_lerobot_robot.py", "test_teleop.py"}


def pytest_collection_modifyitems(config, items):
    for item in items:
        if item.path.name in REALTIME_MODULES:
            item.add_marker(pytest.mark.realtime)
