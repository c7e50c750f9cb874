"""Observation corruption as data: small config objects sampled per episode with a seeded RNG.

The paper's sources of pose error are uniform box noise with a minimum magnitude (Block Grasp,
Nut Insertion, 2-Piece Assembly) and radial noise (Coffee). A sampled offset is recorded in
the episode's data, so any episode can be replayed exactly.

Once the robot touches the object, the error may be lifted (``Observability``): fully (the true
pose becomes observable) or partially (only the first contact position is revealed).
"""

from __future__ import annotations

import abc
import enum
from dataclasses import dataclass, field

import draccus
import numpy as np

from igen_lerobot.core.exceptions import ConfigError

__all__ = ["PoseNoise", "BoxNoise", "RadialNoise", "NoNoise", "Reveal"]


class Reveal(enum.StrEnum):
    """What the robot learns about an object's pose on contact with it."""

    NONE = "none"  # the belief stays corrupted for the whole episode
    FULL = "full"  # the true pose becomes observable from the first contact on
    CONTACT_POSITION = "contact_position"  # only the mean first-contact position is revealed


@dataclass
class PoseNoise(draccus.ChoiceRegistry, abc.ABC):
    """An additive position error [m] on an object's observed pose, drawn once per episode."""

    @property
    def dim(self) -> int:
        return 3

    @abc.abstractmethod
    def sample(self, rng: np.random.Generator) -> np.ndarray:
        """Draw one offset (3,) [m] with the given generator."""

    @abc.abstractmethod
    def contains(self, offset: np.ndarray, atol: float = 1e-12) -> bool:
        """Whether ``offset`` is a value this model can produce (used by tests and validation)."""


@PoseNoise.register_subclass("none")
@dataclass
class NoNoise(PoseNoise):
    """The robot sees the true pose (full demonstrations, uncorrupted evaluation)."""

    def sample(self, rng: np.random.Generator) -> np.ndarray:
        return np.zeros(3)

    def contains(self, offset: np.ndarray, atol: float = 1e-12) -> bool:
        return bool(np.all(np.abs(offset) <= atol))


@PoseNoise.register_subclass("box")
@dataclass
class BoxNoise(PoseNoise):
    """Uniform noise in ``[-half_extent, half_extent]`` per axis with a minimum magnitude.

    ``min_abs`` gives per-axis minimum magnitudes [m] (0 = no minimum). With
    ``require="all"`` every axis with a minimum must satisfy it (Block Grasp: |y| >= 2.5 cm);
    with ``require="any"`` at least one of them must (Nut Insertion, the default: +-4 cm per
    axis with >= 2 cm in one of them).
    """

    half_extent: tuple[float, float, float] = (0.04, 0.04, 0.04)
    min_abs: tuple[float, float, float] = (0.02, 0.02, 0.02)
    require: str = "any"

    def __post_init__(self) -> None:
        half, low = np.asarray(self.half_extent, float), np.asarray(self.min_abs, float)
        if half.shape != (3,) or low.shape != (3,):
            raise ConfigError("corruption.half_extent and corruption.min_abs need 3 values (x, y, z) [m]")
        if np.any(half < 0) or np.any(low < 0):
            raise ConfigError("corruption.half_extent and corruption.min_abs must be >= 0 [m]")
        if np.any(low > half):
            raise ConfigError(
                f"corruption.min_abs {tuple(low)} exceeds corruption.half_extent {tuple(half)} on some axis; "
                "lower min_abs or widen half_extent"
            )
        if self.require not in ("all", "any"):
            raise ConfigError(f"corruption.require must be 'all' or 'any', got {self.require!r}")

    def sample(self, rng: np.random.Generator) -> np.ndarray:
        half, low = np.asarray(self.half_extent, float), np.asarray(self.min_abs, float)
        constrained = low > 0
        if self.require == "all" or not constrained.any():
            # Every constrained axis: sign * U(min, max); others U(-max, max). Exact, no rejection.
            magnitude = np.where(constrained, rng.uniform(low, half), rng.uniform(-half, half))
            sign = np.where(constrained, rng.choice([-1.0, 1.0], size=3), 1.0)
            return magnitude * sign
        # "any": uniform over the box minus the inner box, by rejection (acceptance >= 1 - prod(low/half)).
        for _ in range(10_000):
            offset = rng.uniform(-half, half)
            if np.any(np.abs(offset[constrained]) >= low[constrained]):
                return offset
        raise ConfigError("corruption.min_abs leaves almost no admissible region; lower it")

    def contains(self, offset: np.ndarray, atol: float = 1e-12) -> bool:
        offset = np.asarray(offset, float)
        half, low = np.asarray(self.half_extent, float), np.asarray(self.min_abs, float)
        if np.any(np.abs(offset) > half + atol):
            return False
        constrained = low > 0
        if not constrained.any():
            return True
        meets = np.abs(offset[constrained]) >= low[constrained] - atol
        return bool(meets.all() if self.require == "all" else meets.any())


@PoseNoise.register_subclass("radial")
@dataclass
class RadialNoise(PoseNoise):
    """Offset of uniform direction in the plane ``axes`` with a radius in [r_min, r_max] [m]."""

    r_min: float = 0.02
    r_max: float = 0.04
    axes: tuple[int, ...] = field(default=(0, 1))

    def __post_init__(self) -> None:
        if not 0 <= self.r_min <= self.r_max:
            raise ConfigError(f"corruption needs 0 <= r_min <= r_max, got r_min={self.r_min}, r_max={self.r_max}")
        if len(self.axes) not in (2, 3) or any(a not in (0, 1, 2) for a in self.axes):
            raise ConfigError(f"corruption.axes must be 2 or 3 of (0, 1, 2), got {self.axes}")

    def sample(self, rng: np.random.Generator) -> np.ndarray:
        direction = rng.normal(size=len(self.axes))
        direction /= np.linalg.norm(direction)
        # Uniform over the annulus/shell area, not over the radius.
        k = len(self.axes)
        radius = rng.uniform(self.r_min**k, self.r_max**k) ** (1.0 / k)
        offset = np.zeros(3)
        offset[list(self.axes)] = radius * direction
        return offset

    def contains(self, offset: np.ndarray, atol: float = 1e-12) -> bool:
        offset = np.asarray(offset, float)
        others = [a for a in range(3) if a not in self.axes]
        radius = np.linalg.norm(offset[list(self.axes)])
        return bool(self.r_min - atol <= radius <= self.r_max + atol and np.all(np.abs(offset[others]) <= atol))
