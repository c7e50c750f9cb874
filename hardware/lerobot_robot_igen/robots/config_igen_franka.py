"""LeRobot config of our Franka (``--robot.type=igen_franka``): LeRobot 0.6 ships no Franka.

LeRobot finds the robot class from this config's name (``IgenFrankaConfig`` -> ``IgenFranka`` in
``lerobot_robot_igen.robots.igen_franka``), after importing the ``lerobot_robot_igen`` plugin.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from lerobot.cameras import CameraConfig
from lerobot.robots.config import RobotConfig

from igen_lerobot.core.exceptions import ConfigError
from lerobot_robot_igen.arm.config_arm import REAL_WORLD_FROM_BASE_XYZ, ArmBackendConfig, SimArmBackendConfig
from lerobot_robot_igen.arm.safety import SafetyLimits
from lerobot_robot_igen.teleoperators.config_end_effector_target import HOME_TARGET


@RobotConfig.register_subclass("igen_franka")
@dataclass(kw_only=True)
class IgenFrankaConfig(RobotConfig):
    """A Franka arm (``--robot.arm.type=franky``) or its Block Grasp simulation (``sim``), task-frame targets.

    Example: ``lerobot-replay --robot.type=igen_franka --robot.arm.type=sim --dataset.repo_id=... --dataset.episode=0``
    """

    arm: ArmBackendConfig = field(default_factory=SimArmBackendConfig)
    cameras: dict[str, CameraConfig] = field(default_factory=dict)
    safety: SafetyLimits = field(default_factory=SafetyLimits)
    world_from_base: tuple[float, float, float] = REAL_WORLD_FROM_BASE_XYZ  # real arms; the sim knows its own
    fps: int = 20  # control rate a simulated arm advances at per action
    max_step: float = 0.03  # [m] per action: a far target is approached at this step (and the speed limit)
    max_target_distance: float = 0.3  # [m] a target further than this from the hand is refused (the arm stops)
    grasp_below_width: float = 0.04  # [m] a gripper.pos target below this closes the gripper, else it opens
    home_on_connect: bool = True  # move to `home` when connecting (where igen_ee_target's targets start)
    home: tuple[float, float, float] = HOME_TARGET  # [m] task frame
    trace: str | None = None  # JSON-lines file: every action received, sent and the measured pose after it

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.max_step <= 0:
            raise ConfigError(f"robot.max_step must be > 0 [m], got {self.max_step}")
        if self.max_target_distance < self.max_step:
            raise ConfigError(
                f"robot.max_target_distance ({self.max_target_distance} m) must be >= "
                f"robot.max_step ({self.max_step} m)"
            )
