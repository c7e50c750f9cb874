"""Where a reset puts an object: a region of the table, sampled with the generator it is handed.

The generator is always passed in (never held, never global), so one episode seed decides the
whole scene and a test can replay a placement with an identically seeded generator; the habit of
dm_control's composer placers. Importable without MuJoCo.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from igen_lerobot.core.exceptions import ConfigError

__all__ = ["UniformRegion", "RegionPlacer", "Scene"]


@dataclass(frozen=True)
class UniformRegion:
    """A rectangle on the table: ``extents`` [m] long in x and y, centred on ``center`` [m] (world x, y).

    ``flag`` names the config field the extents came from, so a bad value is refused by that name.
    """

    extents: tuple[float, float]
    center: tuple[float, float] = (0.0, 0.0)
    flag: str = "region"

    def __post_init__(self) -> None:
        extents = np.asarray(self.extents, dtype=float)
        if extents.shape != (2,) or not np.all(np.isfinite(extents)) or extents.min() < 0:
            raise ConfigError(
                f"{self.flag} must be non-negative (x, y) extents [m], got {self.extents}; "
                f"give two lengths, e.g. --{self.flag}='[0.1, 0.1]'"
            )
        center = np.asarray(self.center, dtype=float)
        if center.shape != (2,) or not np.all(np.isfinite(center)):
            raise ConfigError(f"the centre of {self.flag} must be a finite (x, y) point [m], got {self.center}")

    def sample(self, rng: np.random.Generator) -> np.ndarray:
        """One (x, y) point [m], uniform over the region: two draws from ``rng``."""
        center = np.asarray(self.center, dtype=float)
        return center + rng.uniform(-0.5, 0.5, size=2) * np.asarray(self.extents, dtype=float)

    def contains(self, xy: np.ndarray, atol: float = 1e-12) -> bool:
        """Whether the point ``xy`` [m] lies in the region (borders included)."""
        offset = np.abs(np.asarray(xy, dtype=float) - np.asarray(self.center, dtype=float))
        return bool(np.all(offset <= 0.5 * np.asarray(self.extents, dtype=float) + atol))


class Scene(Protocol):
    """What a placer moves: any scene that can set a named object's position."""

    def set_pose(self, name: str, pos: tuple[float, float, float]) -> None:
        """Put object ``name`` at ``pos`` [m], upright and at rest."""


@dataclass(frozen=True)
class RegionPlacer:
    """Puts one object upright at a uniform point of ``region``, its body origin at height ``z`` [m]."""

    obj: str
    region: UniformRegion
    z: float

    def place(self, scene: Scene, rng: np.random.Generator) -> np.ndarray:
        """Place the object in ``scene`` with ``rng``; returns the (x, y) chosen [m]."""
        xy = self.region.sample(rng)
        scene.set_pose(self.obj, (xy[0], xy[1], self.z))
        return xy
