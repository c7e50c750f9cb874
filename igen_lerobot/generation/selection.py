"""Which source segment to replay in a new scene.

* ``random`` (the paper's choice): uniformly among the candidates.
* ``nearest_object`` (MimicGen): among the ``top_k`` segments whose object pose is nearest the
  current one.
* ``nearest_eef``: among the ``top_k`` segments whose start, relative to the object, is nearest
  where the robot is now relative to it (for recoveries: the most similar mistake state).
"""

from __future__ import annotations

import enum
from collections.abc import Sequence

import numpy as np

from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.core.geometry import pose_inv, rotation_angle
from igen_lerobot.generation.sources import SourceSegment

ROTATION_WEIGHT = 0.05  # [m per rad]: 1 rad of orientation counts like 5 cm of position


class Selection(enum.StrEnum):
    """Segment selection strategy."""

    RANDOM = "random"
    NEAREST_OBJECT = "nearest_object"
    NEAREST_EEF = "nearest_eef"


def pose_distance(T_a: np.ndarray, T_b: np.ndarray) -> float:
    """Position distance [m] plus weighted rotation angle."""
    return float(np.linalg.norm(T_a[:3, 3] - T_b[:3, 3]) + ROTATION_WEIGHT * rotation_angle(T_a[:3, :3], T_b[:3, :3]))


def select_segment(
    candidates: Sequence[SourceSegment],
    strategy: Selection,
    rng: np.random.Generator,
    T_world_obj: np.ndarray,
    T_world_eef: np.ndarray,
    top_k: int = 3,
) -> SourceSegment:
    """One segment among ``candidates`` for the current object and end-effector poses."""
    if not candidates:
        raise ConfigError("no source segment to select from")
    strategy = Selection(strategy)
    if strategy is Selection.RANDOM:
        return candidates[int(rng.integers(len(candidates)))]
    if strategy is Selection.NEAREST_OBJECT:
        distances = [pose_distance(s.T_world_obj, T_world_obj) for s in candidates]
    else:
        T_obj_eef = pose_inv(T_world_obj) @ T_world_eef
        distances = [pose_distance(s.T_obj_eef_start, T_obj_eef) for s in candidates]
    nearest = np.argsort(distances, kind="stable")[: max(1, top_k)]
    return candidates[int(rng.choice(nearest))]
