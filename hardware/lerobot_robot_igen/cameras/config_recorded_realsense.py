"""LeRobot config of ``type: igen_realsense``: a D415 by serial, or a RealSense recording played back.

LeRobot's own ``RealSenseCamera`` needs a connected camera's serial number; this one also plays a
``.db3`` recording, so robots, datasets and tests can run the real capture path without the
device. LeRobot finds the camera class from this config's name (``RecordedRealSenseConfig`` ->
``RecordedRealSense`` in ``lerobot_robot_igen.cameras.recorded_realsense``).
"""

from __future__ import annotations

from dataclasses import dataclass

from lerobot.cameras.configs import CameraConfig

from igen_lerobot.core.exceptions import ConfigError


@CameraConfig.register_subclass("igen_realsense")
@dataclass
class RecordedRealSenseConfig(CameraConfig):
    """``--robot.cameras='{front: {type: igen_realsense, serial: "123", width: 640, height: 480, fps: 30}}'``."""

    serial: str | None = None  # None with no recording: the first D415 found
    recording: str | None = None  # a .db3 written by record_rgbd or the RealSense Viewer
    depth: bool = False  # also keep the aligned depth (metres) in `last_depth`

    def __post_init__(self) -> None:
        if self.serial and self.recording:
            raise ConfigError("give the camera a serial (live) or a recording (playback), not both")
