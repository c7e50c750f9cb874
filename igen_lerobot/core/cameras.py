"""Camera streams: which of a task's cameras to render, and the one pixel pipeline for all of them.

A dataset re-rendered from its simulator states (``igen-render``), cameras rendered while
collecting or generating (``--render.cameras``) and the LeRobot env's image observations
(``--env.obs_type=pixels_state``) all go through :func:`render_images`, so a vision policy sees
the same pixels in training and in evaluation: same camera, size, pose and processing.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from igen_lerobot.core.exceptions import ConfigError

if TYPE_CHECKING:
    from igen_lerobot.core.task import TaskEnv, TaskSpec

IMAGE_PREFIX = "observation.images"  # LeRobot's key prefix for camera streams
MIN_SIZE, MAX_SIZE = 16, 1024  # [px]


def image_key(camera: str) -> str:
    """The LeRobot feature name of a camera stream."""
    return f"{IMAGE_PREFIX}.{camera}"


@dataclass
class CameraConfig:
    """Cameras to render (names from the task's ``cameras``) as square RGB images of ``size`` px."""

    cameras: list[str] = field(default_factory=list)  # empty: state only
    size: int = 128

    def check(self, spec: TaskSpec, cameras_flag: str = "--render.cameras", size_flag: str = "--render.size") -> None:
        """Raise :class:`ConfigError` for a camera the task lacks (listing its cameras) or a bad size.

        The flags are the command's own names for the two fields, so the message names what to change.
        """
        check_cameras(spec, self.cameras, cameras_flag)
        if not MIN_SIZE <= int(self.size) <= MAX_SIZE:
            raise ConfigError(
                f"{size_flag}={self.size} px is out of range; use {MIN_SIZE}..{MAX_SIZE} (e.g. 84, 128, 256)"
            )

    def features(self) -> dict[str, dict]:
        """LeRobot video features, one per camera (``observation.images.<camera>``)."""
        shape = (int(self.size), int(self.size), 3)
        return {
            image_key(c): {"dtype": "video", "shape": shape, "names": ["height", "width", "channels"]}
            for c in self.cameras
        }


def check_cameras(spec: TaskSpec, cameras: list[str], flag: str) -> None:
    """Every name one of the task's cameras; none twice."""
    if not spec.cameras and cameras:
        raise ConfigError(f"{flag}: task {spec.name!r} renders no cameras (it has no simulator to render)")
    unknown = [c for c in cameras if c not in spec.cameras]
    if unknown:
        raise ConfigError(f"{flag}: task {spec.name!r} has no camera {unknown[0]!r}; its cameras: {list(spec.cameras)}")
    if len(set(cameras)) != len(cameras):
        raise ConfigError(f"{flag} names a camera twice: {cameras}")


def render_images(env: TaskEnv, cameras: list[str], size: int) -> dict[str, np.ndarray]:
    """(size, size, 3) uint8 RGB per camera of the env's current state."""
    return {c: np.ascontiguousarray(env.render(c, int(size), int(size)), dtype=np.uint8) for c in cameras}
