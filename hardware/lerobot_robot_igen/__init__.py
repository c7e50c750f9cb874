"""igen's real-robot side as a LeRobot robot plugin (``lerobot_robot_*`` is LeRobot's prefix).

LeRobot imports this package on every ``lerobot-*`` command, so it stays light: hardware
libraries (franky, pyrealsense2, Open3D) load only where a backend is built.
"""

from lerobot_robot_igen.config_end_effector_target import EndEffectorTargetConfig
from lerobot_robot_igen.config_igen_franka import IgenFrankaConfig
from lerobot_robot_igen.config_recorded_realsense import RecordedRealSenseConfig

__all__ = ["EndEffectorTargetConfig", "IgenFrankaConfig", "RecordedRealSenseConfig"]
