"""Observation error as data: small config objects sampled per episode with a seeded RNG.

The paper's sources of error are uniform box noise on a position with a minimum magnitude
(Block Grasp, Nut Insertion, 2-Piece Assembly), radial noise on a position (Coffee), and object
geometry: the nut's handle on the other side than the pose estimate says (Nut-and-Peg
Assembly). A model draws one sample per episode; the sample is a short vector whose value names
come from the model (``dx, dy, dz`` for positions, ``flip`` for the handle side), recorded in every
frame of the episode, so any episode can be replayed exactly. :meth:`ErrorModel.apply` turns the
true pose of the corrupted object into the pose the robot believes.
"""

from __future__ import annotations

import abc
from dataclasses import dataclass, field

import draccus
import numpy as np

from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.core.geometry import rot_z

__all__ = ["ErrorModel", "BoxNoise", "RadialNoise", "NoNoise", "YawFlip", "POSITION_ERROR_NAMES"]

POSITION_ERROR_NAMES = ("dx", "dy", "dz")


@dataclass
class ErrorModel(draccus.ChoiceRegistry, abc.ABC):
    """An error on one object's observed pose, drawn once per episode."""

    @property
    @abc.abstractmethod
    def names(self) -> tuple[str, ...]:
        """Names of the sample's values, in order (the object's name is prefixed in datasets)."""

    @abc.abstractmethod
    def sample(self, rng: np.random.Generator) -> np.ndarray:
        """Draw one sample with the given generator."""

    @abc.abstractmethod
    def contains(self, sample: np.ndarray, atol: float = 1e-12) -> bool:
        """Whether ``sample`` is a value this model can produce (tests and validation)."""

    @abc.abstractmethod
    def apply(self, T_world_obj: np.ndarray, sample: np.ndarray) -> np.ndarray:
        """The pose the robot believes, given the true pose ``T_world_obj`` and this episode's sample."""

    @property
    def type_name(self) -> str:
        """The name this model is chosen by (``--env.corruption.type=...``)."""
        return ErrorModel.get_choice_name(type(self))

    def checked(self, sample: np.ndarray, field_name: str = "corruption") -> np.ndarray:
        """``sample`` as a float vector of this model's size, or a clear error naming ``field_name``."""
        sample = np.asarray(sample, dtype=float).reshape(-1)
        if sample.shape != (len(self.names),):
            raise ConfigError(
                f"{field_name} must hold {len(self.names)} values {self.names} for error model "
                f"{self.type_name!r}, got shape {sample.shape}"
            )
        return sample


class _PositionOffset(ErrorModel):
    """A world-frame offset [m] added to the object's position; the orientation stays true."""

    @property
    def names(self) -> tuple[str, ...]:
        return POSITION_ERROR_NAMES

    def apply(self, T_world_obj: np.ndarray, sample: np.ndarray) -> np.ndarray:
        believed = np.array(T_world_obj, dtype=float)
        believed[:3, 3] += np.asarray(sample, dtype=float)
        return believed


@ErrorModel.register_subclass("none")
@dataclass
class NoNoise(ErrorModel):
    """The robot sees the true pose (full demonstrations, uncorrupted evaluation).

    Its all-zero sample takes the shape of the task's own error (``layout``, set by the task's
    config), so uncorrupted and corrupted datasets of one task share one schema.
    """

    layout: tuple[str, ...] = POSITION_ERROR_NAMES

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.layout)

    def sample(self, rng: np.random.Generator) -> np.ndarray:
        return np.zeros(len(self.layout))

    def contains(self, sample: np.ndarray, atol: float = 1e-12) -> bool:
        return bool(np.all(np.abs(np.asarray(sample, dtype=float)) <= atol))

    def apply(self, T_world_obj: np.ndarray, sample: np.ndarray) -> np.ndarray:
        return np.array(T_world_obj, dtype=float)


@ErrorModel.register_subclass("box")
@dataclass
class BoxNoise(_PositionOffset):
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

    def contains(self, sample: np.ndarray, atol: float = 1e-12) -> bool:
        offset = np.asarray(sample, float)
        half, low = np.asarray(self.half_extent, float), np.asarray(self.min_abs, float)
        if np.any(np.abs(offset) > half + atol):
            return False
        constrained = low > 0
        if not constrained.any():
            return True
        meets = np.abs(offset[constrained]) >= low[constrained] - atol
        return bool(meets.all() if self.require == "all" else meets.any())


@ErrorModel.register_subclass("radial")
@dataclass
class RadialNoise(_PositionOffset):
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

    def contains(self, sample: np.ndarray, atol: float = 1e-12) -> bool:
        offset = np.asarray(sample, float)
        others = [a for a in range(3) if a not in self.axes]
        radius = np.linalg.norm(offset[list(self.axes)])
        return bool(self.r_min - atol <= radius <= self.r_max + atol and np.all(np.abs(offset[others]) <= atol))


@ErrorModel.register_subclass("flip")
@dataclass
class YawFlip(ErrorModel):
    """A geometry error: with probability ``probability`` the object is turned by ``angle`` about its z axis.

    Nut-and-Peg Assembly: for an identical observed nut pose the handle may be on either side
    (true yaw = observed + pi). The sample is ``flip`` in {0, 1}.
    """

    probability: float = 0.5
    angle: float = float(np.pi)  # [rad]

    def __post_init__(self) -> None:
        if not 0.0 <= self.probability <= 1.0:
            raise ConfigError(f"corruption.probability must be in [0, 1], got {self.probability}")

    @property
    def names(self) -> tuple[str, ...]:
        return ("flip",)

    def sample(self, rng: np.random.Generator) -> np.ndarray:
        return np.array([1.0 if rng.uniform() < self.probability else 0.0])

    def contains(self, sample: np.ndarray, atol: float = 1e-12) -> bool:
        value = np.asarray(sample, dtype=float).reshape(-1)
        if value.shape != (1,):
            return False
        allowed = [v for v, p in ((0.0, 1.0 - self.probability), (1.0, self.probability)) if p > 0]
        return any(abs(value[0] - v) <= atol for v in allowed)

    def apply(self, T_world_obj: np.ndarray, sample: np.ndarray) -> np.ndarray:
        flip = float(np.asarray(sample, dtype=float).reshape(-1)[0])
        believed = np.array(T_world_obj, dtype=float)
        believed[:3, :3] = believed[:3, :3] @ rot_z(-self.angle * flip)
        return believed
