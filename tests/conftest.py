import os

os.environ.setdefault("MUJOCO_GL", "egl")
os.environ.setdefault("HF_HUB_OFFLINE", "1")  # tests never reach the Hub

import pytest  # noqa: E402


@pytest.fixture(scope="session")
def block_grasp_config():
    from igen_lerobot.env_config import task_config_class

    return task_config_class("block_grasp")()


@pytest.fixture(scope="session")
def block_grasp_env(block_grasp_config):
    env = block_grasp_config.make_task_env()
    yield env
    env.close()
