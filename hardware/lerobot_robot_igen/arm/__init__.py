"""The arm: the driver protocol, the safety layer around it, and the backends that implement it.

Importing the package registers the ``--robot.type`` / ``--robot.arm.type`` choices: ``sim``
(:mod:`~lerobot_robot_igen.arm.config_arm`) and ``franky``
(:mod:`~lerobot_robot_igen.arm.config_franky_arm`). Each backend's settings live in a light config
module; its robot library (MuJoCo, franky) loads only when its driver is built.
"""

from lerobot_robot_igen.arm.config_arm import ArmBackendConfig, SimArmBackendConfig
from lerobot_robot_igen.arm.config_franky_arm import FrankyArmConfig

__all__ = ["ArmBackendConfig", "FrankyArmConfig", "SimArmBackendConfig"]
