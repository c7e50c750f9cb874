"""LeRobot config of ``--teleop.type=igen_ee_target``: a keyboard or gamepad as end-effector targets."""

from __future__ import annotations

from dataclasses import dataclass, field

from lerobot.teleoperators.config import TeleoperatorConfig

from igen_lerobot.core.exceptions import ConfigError
from lerobot_robot_igen.arm.safety import SafetyLimits

HOME_TARGET = (-0.05, 0.0, 1.0)  # [m] task frame: Block Grasp's start pose, where igen_franka homes to


@TeleoperatorConfig.register_subclass("igen_ee_target")
@dataclass
class EndEffectorTargetConfig(TeleoperatorConfig):
    """Integrates an end-effector teleop's deltas into the absolute targets ``igen_franka`` takes.

    Example: ``lerobot-record --robot.type=igen_franka --teleop.type=igen_ee_target
    --teleop.device=keyboard_ee ...`` (or ``--teleop.device=gamepad``).
    """

    # a LeRobot teleoperator giving delta_x/y/z + gripper, by type name (its defaults): a name rather
    # than a nested teleop config, which LeRobot's parser cannot hold inside a teleop config
    device: str = "keyboard_ee"
    start: tuple[float, float, float] = HOME_TARGET  # the robot homes here on connect
    step: float = 0.005  # [m] per control period while a direction is held (0.1 m/s at 20 Hz)
    workspace: SafetyLimits = field(default_factory=SafetyLimits)  # targets stay inside its box

    def device_config(self) -> TeleoperatorConfig:
        """The wrapped device's LeRobot config (its defaults)."""
        try:
            return TeleoperatorConfig.get_choice_class(self.device)()
        except KeyError as err:
            known = sorted(TeleoperatorConfig.get_known_choices())
            raise ConfigError(f"teleop.device={self.device!r} is not a LeRobot teleoperator; known: {known}") from err

    def __post_init__(self) -> None:
        if self.device == "igen_ee_target":
            raise ConfigError("teleop.device must be a device such as keyboard_ee or gamepad, not igen_ee_target")
        if self.step <= 0:
            raise ConfigError(f"teleop.step must be > 0 [m per period], got {self.step}")
