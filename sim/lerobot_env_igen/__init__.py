"""igen simulated tasks as a LeRobot env plugin.

LeRobot imports every installed distribution whose name starts with ``lerobot_env_`` (see
``lerobot.utils.import_utils.register_third_party_plugins``); importing this package imports the
``config`` module of every task folder in it, which registers the task's env config
(``--env.type=<task>``), and registers each task's gymnasium id. A task is a folder: adding one
needs no edit here. It imports neither MuJoCo nor robosuite: those load when an env is built.
"""

import importlib
import importlib.util
import os
import pkgutil

# Headless machines (and lerobot-eval's video rendering on them) need MuJoCo's EGL backend; it
# must be chosen before MuJoCo is first imported. An explicit MUJOCO_GL always wins.
if "MUJOCO_GL" not in os.environ and not os.environ.get("DISPLAY"):
    os.environ["MUJOCO_GL"] = "egl"

from igen_lerobot.core.env_config import TaskEnvConfig, register_gym_env  # noqa: E402
from lerobot_env_igen.quiet import silence_robosuite_notices  # noqa: E402

silence_robosuite_notices()


def _task_configs() -> dict[str, type[TaskEnvConfig]]:
    """The config class of every task folder (a subpackage with a ``config`` module)."""
    found = {}
    for module in pkgutil.iter_modules(__path__):
        if not module.ispkg or not importlib.util.find_spec(f"{__name__}.{module.name}.config"):
            continue
        config = importlib.import_module(f"{__name__}.{module.name}.config")
        for value in vars(config).values():
            if isinstance(value, type) and issubclass(value, TaskEnvConfig) and value.__module__ == config.__name__:
                found[module.name] = value
    return found


TASK_CONFIGS = _task_configs()
for _config_cls in TASK_CONFIGS.values():
    register_gym_env(_config_cls)

__all__ = ["TASK_CONFIGS"]
