"""The motion limits, checked in one place whatever drives the robot (see ``SafeArm``).

Limits live in the **task frame** (the frame the policy was trained in: Block Grasp's table top is
at z = 0.8 m, the cube region centred on x = y = 0), so one set of numbers guards the simulated
and the real arm alike. Every Cartesian target passes through :meth:`SafetyGuard.filter_target`:
a target just outside the workspace box is clamped onto it (a policy pressing a centimetre into
the table is normal; the table stops it in sim too), a target far outside is refused, and the
step is limited to the maximum speed at the control rate. :class:`Watchdog` stops the robot when
commands go stale. Units: metres, seconds.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from igen_lerobot.core.exceptions import ConfigError
from lerobot_robot_igen.errors import HardwareError


class SafetyViolationError(HardwareError):
    """A command would break a safety limit; the robot must stop."""


@dataclass(frozen=True)
class SafetyLimits:
    """Workspace box in the task frame [m], how far outside it a target may be clamped, speed limit [m/s]."""

    # Block Grasp: 50 x 70 cm around the 20 x 30 cm cube region, from 5 mm above the table top
    # (the end effector is between the finger pads: it never needs to go lower) to 35 cm above it.
    workspace_min: tuple[float, float, float] = (-0.25, -0.35, 0.805)
    workspace_max: tuple[float, float, float] = (0.25, 0.35, 1.15)
    clamp_margin: float = 0.05  # [m] targets further outside the box than this are refused
    max_speed: float = 0.5  # [m/s]
    watchdog_timeout: float = 0.2  # [s] four missed 20 Hz periods

    def __post_init__(self) -> None:
        low, high = np.asarray(self.workspace_min, float), np.asarray(self.workspace_max, float)
        if low.shape != (3,) or high.shape != (3,):
            raise ConfigError("safety.workspace_min and safety.workspace_max need 3 values (x, y, z) [m]")
        if np.any(low >= high):
            raise ConfigError(f"safety.workspace_min {tuple(low)} must be below safety.workspace_max {tuple(high)}")
        if self.clamp_margin < 0:
            raise ConfigError(f"safety.clamp_margin must be >= 0 [m], got {self.clamp_margin}")
        if self.max_speed <= 0:
            raise ConfigError(f"safety.max_speed must be > 0 [m/s], got {self.max_speed}")
        if self.watchdog_timeout <= 0:
            raise ConfigError(f"safety.watchdog_timeout must be > 0 [s], got {self.watchdog_timeout}")


@dataclass
class SafetyGuard:
    """Checks and limits Cartesian targets against :class:`SafetyLimits`."""

    limits: SafetyLimits = field(default_factory=SafetyLimits)

    def inside(self, position: np.ndarray, margin: float = 0.0) -> bool:
        """Whether ``position`` is in the workspace box grown by ``margin`` [m]."""
        position = np.asarray(position, float)
        low = np.asarray(self.limits.workspace_min) - margin
        high = np.asarray(self.limits.workspace_max) + margin
        return bool(np.all(position >= low) and np.all(position <= high))

    def _describe(self, what: str, position: np.ndarray) -> str:
        return (
            f"{what} {np.round(position, 4).tolist()} m is outside the workspace "
            f"{self.limits.workspace_min}..{self.limits.workspace_max} m (task frame) by more than "
            f"safety.clamp_margin={self.limits.clamp_margin} m"
        )

    def check_position(self, position: np.ndarray) -> None:
        """Refuse a measured end-effector position outside the box (beyond the clamp margin)."""
        if not self.inside(position, self.limits.clamp_margin):
            raise SafetyViolationError(self._describe("the end effector at", position))

    def filter_target(self, current: np.ndarray, target: np.ndarray, period: float) -> np.ndarray:
        """A target inside the box and reachable within ``period`` [s] at the speed limit.

        Raises :class:`SafetyViolationError` for a non-finite target or one further outside the
        box than ``clamp_margin``.
        """
        current, target = np.asarray(current, float), np.asarray(target, float)
        if not np.all(np.isfinite(target)):
            raise SafetyViolationError(f"target {target.tolist()} is not finite")
        if not self.inside(target, self.limits.clamp_margin):
            raise SafetyViolationError(self._describe("target", target))
        target = np.clip(target, self.limits.workspace_min, self.limits.workspace_max)
        step = target - current
        max_step = self.limits.max_speed * period
        norm = float(np.linalg.norm(step))
        if norm > max_step:
            step *= max_step / norm
        return current + step


class Watchdog:
    """Calls ``on_timeout`` once when :meth:`feed` has not been called for ``timeout`` seconds."""

    def __init__(self, timeout: float, on_timeout: Callable[[], None], clock: Callable[[], float] = time.monotonic):
        self.timeout = timeout
        self._on_timeout = on_timeout
        self._clock = clock
        self._last = clock()
        self.tripped = False

    def feed(self) -> None:
        self._last = self._clock()

    def check(self) -> bool:
        """Trip if stale; returns whether the watchdog has tripped."""
        if not self.tripped and self._clock() - self._last > self.timeout:
            self.tripped = True
            self._on_timeout()
        return self.tripped
