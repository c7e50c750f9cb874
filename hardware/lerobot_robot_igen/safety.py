"""The one place where motion limits are enforced, whatever drives the robot.

Every Cartesian command passes through :meth:`SafetyGuard.filter_target`: it is refused if
the commanded end effector would leave the workspace box, and its step is limited to the
maximum speed at the control rate. :class:`Watchdog` stops the robot when commands or pose
estimates go stale. Units: metres, seconds.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from igen_lerobot.exceptions import ConfigError, IgenError


class SafetyViolationError(IgenError, RuntimeError):
    """A command would break a safety limit; the robot must stop."""


@dataclass(frozen=True)
class SafetyLimits:
    """Workspace box in the robot base frame [m] and the end effector's speed limit [m/s]."""

    workspace_min: tuple[float, float, float] = (0.25, -0.35, 0.02)
    workspace_max: tuple[float, float, float] = (0.75, 0.35, 0.45)
    max_speed: float = 0.25
    watchdog_timeout: float = 0.2  # [s] four missed 20 Hz periods

    def __post_init__(self) -> None:
        low, high = np.asarray(self.workspace_min, float), np.asarray(self.workspace_max, float)
        if low.shape != (3,) or high.shape != (3,):
            raise ConfigError("safety.workspace_min and safety.workspace_max need 3 values (x, y, z) [m]")
        if np.any(low >= high):
            raise ConfigError(f"safety.workspace_min {tuple(low)} must be below safety.workspace_max {tuple(high)}")
        if self.max_speed <= 0:
            raise ConfigError(f"safety.max_speed must be > 0 [m/s], got {self.max_speed}")
        if self.watchdog_timeout <= 0:
            raise ConfigError(f"safety.watchdog_timeout must be > 0 [s], got {self.watchdog_timeout}")


@dataclass
class SafetyGuard:
    """Checks and limits Cartesian targets against :class:`SafetyLimits`."""

    limits: SafetyLimits = field(default_factory=SafetyLimits)

    def inside(self, position: np.ndarray) -> bool:
        position = np.asarray(position, float)
        return bool(np.all(position >= self.limits.workspace_min) and np.all(position <= self.limits.workspace_max))

    def filter_target(self, current: np.ndarray, target: np.ndarray, period: float) -> np.ndarray:
        """A target reachable within ``period`` [s] at the speed limit, or :class:`SafetyViolationError`."""
        current, target = np.asarray(current, float), np.asarray(target, float)
        if not np.all(np.isfinite(target)):
            raise SafetyViolationError(f"target {target.tolist()} is not finite")
        if not self.inside(target):
            raise SafetyViolationError(
                f"target {np.round(target, 4).tolist()} m is outside the workspace "
                f"{self.limits.workspace_min}..{self.limits.workspace_max} m (robot base frame)"
            )
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
