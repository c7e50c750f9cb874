"""igen simulated tasks as a LeRobot env plugin.

LeRobot imports every installed distribution whose name starts with ``lerobot_env_`` (see
``lerobot.utils.import_utils.register_third_party_plugins``); importing this package registers
our env configs (``--env.type=block_grasp``) and their gymnasium ids. It imports neither MuJoCo
nor robosuite: those load when an env is built.
"""

import os

import gymnasium as gym

# Headless machines (and lerobot-eval's video rendering on them) need MuJoCo's EGL backend; it
# must be chosen before MuJoCo is first imported. An explicit MUJOCO_GL always wins.
if "MUJOCO_GL" not in os.environ and not os.environ.get("DISPLAY"):
    os.environ["MUJOCO_GL"] = "egl"

from lerobot_env_igen.block_grasp.config import BlockGraspEnvConfig

__all__ = ["BlockGraspEnvConfig"]

_GYM_ENTRY_POINT = "igen_lerobot.core.gym_env:TaskGymEnv"

for _config_cls in (BlockGraspEnvConfig,):
    _gym_id = f"lerobot_env_igen/{_config_cls.task}"
    if _gym_id not in gym.registry:
        gym.register(id=_gym_id, entry_point=_GYM_ENTRY_POINT, disable_env_checker=True)
