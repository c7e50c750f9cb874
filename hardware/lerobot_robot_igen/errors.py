"""One root for the errors the hardware side raises on purpose, under the project's :class:`IgenError`.

Each kind keeps its own error beside the code that raises it (mink's per-subpackage exceptions):
:class:`~lerobot_robot_igen.arm.driver.DriverError` (the arm refused or lost a command),
:class:`~lerobot_robot_igen.arm.safety.SafetyViolationError` (a limit would be broken),
:class:`~lerobot_robot_igen.cameras.realsense.CameraError` (no frames) and
:class:`~lerobot_robot_igen.perception.cube_pose.PerceptionError` (no trustworthy pose). Catching
:class:`HardwareError` catches all of them, and nothing from the robot libraries themselves.
"""

from igen_lerobot.core.exceptions import IgenError

__all__ = ["HardwareError"]


class HardwareError(IgenError, RuntimeError):
    """Root of the arm, safety, camera and perception errors; the message says what stopped and why."""
