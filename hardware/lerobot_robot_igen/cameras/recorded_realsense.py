"""A RealSense camera (live or recorded) as a LeRobot ``Camera``, over ``realsense.RealSenseRGBD``."""

from __future__ import annotations

from typing import Any

import numpy as np
from lerobot.cameras.camera import Camera

from lerobot_robot_igen.cameras.config_recorded_realsense import RecordedRealSenseConfig


class RecordedRealSense(Camera):
    """Color frames (RGB, H x W x 3) for LeRobot; the aligned depth of the last frame in ``last_depth``."""

    def __init__(self, config: RecordedRealSenseConfig) -> None:
        super().__init__(config)
        self.config = config
        self.rgbd = None
        self.last_depth: np.ndarray | None = None

    @property
    def is_connected(self) -> bool:
        return self.rgbd is not None

    @staticmethod
    def find_cameras() -> list[dict[str, Any]]:
        from lerobot_robot_igen.cameras.realsense import connected_serials

        return [{"type": "igen_realsense", "id": serial} for serial in connected_serials()]

    def connect(self, warmup: bool = True) -> None:
        from lerobot_robot_igen.cameras.realsense import CameraError, RealSenseConfig, RealSenseRGBD

        cfg = self.config
        rgbd = RealSenseRGBD(
            RealSenseConfig(
                serial=cfg.serial,
                recording=cfg.recording,
                width=cfg.width or 640,
                height=cfg.height or 480,
                fps=cfg.fps or 30,
            )
        ).start()
        intrinsics = rgbd.intrinsics
        if (cfg.width, cfg.height) != (None, None) and (intrinsics.width, intrinsics.height) != (cfg.width, cfg.height):
            rgbd.stop()
            raise CameraError(
                f"{rgbd.source} delivers {intrinsics.width}x{intrinsics.height}, the config asks for "
                f"{cfg.width}x{cfg.height}: set width/height to what the camera or recording has"
            )
        self.rgbd = rgbd

    def read(self) -> np.ndarray:
        if self.rgbd is None:
            raise RuntimeError(f"{self} is not connected")
        color, depth, _ = self.rgbd.read()
        if self.config.depth:
            self.last_depth = depth
        return color

    def async_read(self, timeout_ms: float = 200) -> np.ndarray:
        return self.read()  # frames arrive at the stream rate; read() blocks until the next one

    def read_latest(self, max_age_ms: int = 500) -> np.ndarray:
        return self.read()

    def disconnect(self) -> None:
        if self.rgbd is not None:
            self.rgbd.stop()
            self.rgbd = None
