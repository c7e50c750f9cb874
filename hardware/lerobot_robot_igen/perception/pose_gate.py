"""Which cube estimates the deployment loop may act on: confident ones the cube could have reached.

The estimator rejects frames it cannot explain; this gate adds what only the loop knows: time.
The cube moves only when the gripper moves it, and the gripper is held to the safety layer's
speed limit, so an estimate further from the last accepted one than that speed allows (plus the
estimator's noise) is a wrong estimate, not a moved cube. Rejected frames are bridged by the
last accepted estimate while it is fresh (the loop's ``max_pose_age``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from igen_lerobot.core.exceptions import ConfigError
from lerobot_robot_igen.perception.pose_source import PoseReading


@dataclass
class PoseGateSettings:
    """Thresholds of the gate (``--pose_gate.*`` in igen-deploy)."""

    max_cube_speed: float = 0.5  # [m/s] the cube moves with the gripper at most: the safety speed limit
    jump_tolerance: float = 0.01  # [m] estimator noise allowed on top of the motion
    min_confidence: float = 0.8  # estimates the estimator itself rates lower are not acted on

    def __post_init__(self) -> None:
        if self.max_cube_speed <= 0:
            raise ConfigError(f"pose_gate.max_cube_speed must be > 0 [m/s], got {self.max_cube_speed}")
        if self.jump_tolerance < 0:
            raise ConfigError(f"pose_gate.jump_tolerance must be >= 0 [m], got {self.jump_tolerance}")
        if not 0 <= self.min_confidence <= 1:
            raise ConfigError(f"pose_gate.min_confidence must be in [0, 1], got {self.min_confidence}")


class PoseGate:
    """Judges each reading against the last accepted one; keeps that one."""

    def __init__(self, settings: PoseGateSettings | None = None) -> None:
        self.settings = settings or PoseGateSettings()
        self.last_position: np.ndarray | None = None
        self.last_time = -np.inf

    def reset(self) -> None:
        self.last_position, self.last_time = None, -np.inf

    def judge(self, reading: PoseReading, T_world_cube: np.ndarray, loop_time: float) -> tuple[str, str] | None:
        """None if the reading is accepted (and becomes the reference), else ``(kind, reason)``."""
        cfg = self.settings
        estimate = reading.estimate
        if estimate is not None and estimate.confidence < cfg.min_confidence:
            return "low_confidence", f"confidence {estimate.confidence:.2f} < min_confidence {cfg.min_confidence}"
        position = T_world_cube[:3, 3]
        if self.last_position is not None:
            moved = float(np.linalg.norm(position - self.last_position))
            allowed = cfg.max_cube_speed * (loop_time - self.last_time) + cfg.jump_tolerance
            if moved > allowed:
                return "jump", (
                    f"the estimate jumped {1000 * moved:.0f} mm in {loop_time - self.last_time:.2f} s; "
                    f"the cube can move at most {1000 * allowed:.0f} mm"
                )
        self.last_position, self.last_time = position.copy(), loop_time
        return None
