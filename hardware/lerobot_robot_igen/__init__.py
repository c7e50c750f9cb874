"""igen's real-robot side as a LeRobot robot plugin (``lerobot_robot_*`` is LeRobot's prefix).

Laid out as LeRobot's own packages are: ``arm/`` (driver protocol, safety layer, backends),
``cameras/``, ``perception/``, ``deploy/`` (igen-deploy), ``robots/`` and ``teleoperators/``.

LeRobot imports this package on every ``lerobot-*`` command, so it stays light: importing it
registers the ``igen_franka`` robot, the ``igen_ee_target`` teleoperator and the
``recorded_realsense`` camera (their config modules), and hardware libraries (franky,
pyrealsense2, Open3D) load only where a backend is built.
"""

from lerobot_robot_igen.cameras.config_recorded_realsense import RecordedRealSenseConfig
from lerobot_robot_igen.robots.config_igen_franka import IgenFrankaConfig
from lerobot_robot_igen.teleoperators.config_end_effector_target import EndEffectorTargetConfig

__all__ = ["EndEffectorTargetConfig", "IgenFrankaConfig", "RecordedRealSenseConfig"]
