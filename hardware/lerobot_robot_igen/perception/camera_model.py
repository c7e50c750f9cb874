"""Pinhole intrinsics and camera-to-robot extrinsics (from a calibration file).

Conventions: OpenCV camera frame (x right, y down, z forward), pixel ``(u, v)`` = (column, row)
with ``(0, 0)`` the centre of the top-left pixel; depth in metres along the optical axis.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.core.geometry import pos_quat_to_pose


@dataclass(frozen=True)
class Intrinsics:
    """A pinhole camera (no distortion: the D415's color stream is rectified)."""

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float

    @classmethod
    def d415_color_640x480(cls) -> Intrinsics:
        """Typical factory intrinsics of a D415 color stream at 640x480 (about 69 x 42 degrees)."""
        return cls(width=640, height=480, fx=615.0, fy=615.0, cx=319.5, cy=239.5)

    @classmethod
    def from_vertical_fov(cls, width: int, height: int, fovy_deg: float) -> Intrinsics:
        """Square pixels, principal point at the image centre (a rendered camera)."""
        f = (height / 2) / np.tan(np.deg2rad(fovy_deg) / 2)
        return cls(width=width, height=height, fx=f, fy=f, cx=width / 2 - 0.5, cy=height / 2 - 0.5)

    @property
    def vertical_fov_deg(self) -> float:
        return float(np.rad2deg(2 * np.arctan((self.height / 2) / self.fy)))

    def back_project(self, rows: np.ndarray, cols: np.ndarray, depth_m: np.ndarray) -> np.ndarray:
        """(N, 3) points in the camera frame for pixels ``(rows, cols)`` at ``depth_m``."""
        z = depth_m.astype(np.float64)
        return np.stack([(cols - self.cx) * z / self.fx, (rows - self.cy) * z / self.fy, z], axis=1)


def load_extrinsics(path: str | Path) -> np.ndarray:
    """``T_base_camera`` (4x4) from a calibration JSON.

    Accepted forms: ``{"T_base_camera": [[...4x4...]]}`` or
    ``{"translation": [x, y, z], "quaternion_xyzw": [qx, qy, qz, qw]}`` (camera pose in the robot base frame).
    """
    path = Path(path)
    if not path.exists():
        raise ConfigError(
            f"camera calibration {path} not found; run a hand-eye calibration and save T_base_camera there "
            '(JSON: {"translation": [x, y, z], "quaternion_xyzw": [qx, qy, qz, qw]})'
        )
    try:
        data = json.loads(path.read_text())
    except json.JSONDecodeError as err:
        raise ConfigError(f"camera calibration {path} is not valid JSON: {err}") from err
    if "T_base_camera" in data:
        T = np.asarray(data["T_base_camera"], dtype=float)
        if T.shape != (4, 4):
            raise ConfigError(f"{path}: T_base_camera must be 4x4, got shape {T.shape}")
        rotation = T[:3, :3]
        if not np.allclose(rotation @ rotation.T, np.eye(3), atol=1e-4) or np.linalg.det(rotation) < 0:
            raise ConfigError(f"{path}: T_base_camera's rotation block is not a rotation matrix")
        return T
    if "translation" in data and "quaternion_xyzw" in data:
        quat = np.asarray(data["quaternion_xyzw"], dtype=float)
        if quat.shape != (4,) or not np.isclose(np.linalg.norm(quat), 1.0, atol=1e-3):
            raise ConfigError(f"{path}: quaternion_xyzw must be a unit quaternion [qx, qy, qz, qw]")
        return pos_quat_to_pose(np.asarray(data["translation"], dtype=float), quat)
    raise ConfigError(f"{path} holds neither T_base_camera nor translation + quaternion_xyzw")


def save_extrinsics(path: str | Path, T_base_camera: np.ndarray) -> None:
    """Write ``T_base_camera`` in the format :func:`load_extrinsics` reads."""
    Path(path).write_text(json.dumps({"T_base_camera": np.asarray(T_base_camera).tolist()}, indent=2))
