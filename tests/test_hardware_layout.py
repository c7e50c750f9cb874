"""Importing the hardware plugin registers its LeRobot choices and loads no robot library."""

import subprocess
import sys

PROBE = """
import sys
import lerobot_robot_igen
from lerobot.cameras.configs import CameraConfig
from lerobot.robots.config import RobotConfig
from lerobot.teleoperators.config import TeleoperatorConfig
from lerobot_robot_igen.arm.config_arm import ArmBackendConfig

print(RobotConfig.get_choice_class("igen_franka").__name__)
print(TeleoperatorConfig.get_choice_class("igen_ee_target").__name__)
print(CameraConfig.get_choice_class("igen_realsense").__name__)
print(sorted(ArmBackendConfig.get_known_choices()))
heavy = ("franky", "pyrealsense2", "open3d", "mujoco", "lerobot_robot_igen.arm.franky_arm")
print([name for name in heavy if name in sys.modules])
"""


def test_the_plugin_registers_robot_teleoperator_camera_and_arms_without_loading_hardware_libraries():
    out = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True, check=True, timeout=120)
    lines = out.stdout.strip().splitlines()
    assert lines == [
        "IgenFrankaConfig",
        "EndEffectorTargetConfig",
        "RecordedRealSenseConfig",
        "['franky', 'sim']",
        "[]",
    ], out.stderr
