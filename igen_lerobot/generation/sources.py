"""Source episodes cut into object-centric segments the generator can move into new scenes.

A demonstration gives one segment per subtask. An intervention episode gives, per subtask,
alternating *mistake* (policy frames) and *recovery* (operator frames) segments. Every segment
keeps the true pose of its subtask's object at the segment's first frame (the frame it is
relative to) and the end-effector goals its actions set.
"""

from __future__ import annotations

import enum
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from igen_lerobot.core.episode import Episode
from igen_lerobot.core.exceptions import DatasetSchemaError, TaskMismatchError
from igen_lerobot.core.geometry import pose_inv
from igen_lerobot.core.task import FrameSource, TaskSpec


class SegmentRole(enum.StrEnum):
    """What a segment shows."""

    SUBTASK = "subtask"  # a demonstration's whole subtask
    MISTAKE = "mistake"  # the policy acting on a wrong belief
    RECOVERY = "recovery"  # the operator correcting it


@dataclass(frozen=True)
class SourceSegment:
    """A run of frames relative to one object."""

    episode: int  # index of the source episode
    subtask: int
    role: SegmentRole
    object_name: str
    T_world_obj: np.ndarray  # (4, 4) true object pose at the first frame
    eef: np.ndarray  # (N, 4, 4) achieved end-effector poses
    targets: np.ndarray  # (N, 4, 4) end-effector goals set by the recorded actions
    gripper_closed: np.ndarray  # (N,) bool
    corruption: np.ndarray  # the source episode's pose error
    source_seed: int = 0
    T_world_objects: dict[str, np.ndarray] = field(default_factory=dict)  # every object's true pose at the first frame

    @property
    def length(self) -> int:
        return int(self.targets.shape[0])

    @property
    def T_obj_eef_start(self) -> np.ndarray:
        """Where the segment starts relative to its object (used to pick the nearest recovery)."""
        return pose_inv(self.T_world_obj) @ self.eef[0]


@dataclass
class SourceLibrary:
    """All segments of a source dataset, indexed by (role, subtask)."""

    spec: TaskSpec
    segments: list[SourceSegment] = field(default_factory=list)
    episodes: int = 0

    def select(self, role: SegmentRole, subtask: int) -> list[SourceSegment]:
        return [s for s in self.segments if s.role == role and s.subtask == subtask]

    def segments_of(self, role: SegmentRole) -> list[SourceSegment]:
        return [s for s in self.segments if s.role == role]

    def require(self, role: SegmentRole, subtask: int) -> list[SourceSegment]:
        found = self.select(role, subtask)
        if not found:
            raise DatasetSchemaError(
                f"the sources have no {role.value} segment for subtask {subtask} "
                f"({self.spec.subtasks[subtask].name!r}); record sources that cover it"
            )
        return found


TargetFromAction = Callable[[np.ndarray, np.ndarray], np.ndarray]
GripperFromAction = Callable[[np.ndarray], bool]


def _runs(values: np.ndarray) -> list[tuple[int, int]]:
    """Half-open index ranges of equal consecutive values."""
    edges = np.flatnonzero(np.diff(values)) + 1
    starts = np.concatenate([[0], edges])
    ends = np.concatenate([edges, [len(values)]])
    return list(zip(starts.tolist(), ends.tolist(), strict=True))


def _segment(
    ep: Episode,
    index: int,
    rows: slice,
    subtask: int,
    role: SegmentRole,
    spec: TaskSpec,
    target_from_action: TargetFromAction,
    gripper_from_action: GripperFromAction,
) -> SourceSegment:
    obj = spec.subtasks[subtask].object_name
    eef = spec.eef_poses(ep.state[rows])
    actions = ep.action[rows]
    targets = np.stack([target_from_action(T, a) for T, a in zip(eef, actions, strict=True)])
    return SourceSegment(
        episode=index,
        subtask=subtask,
        role=role,
        object_name=obj,
        T_world_obj=spec.object_poses(ep.true_object_pose[rows.start], obj),
        eef=eef,
        targets=targets,
        gripper_closed=np.array([gripper_from_action(a) for a in actions]),
        corruption=np.asarray(ep.corruption, dtype=float),
        source_seed=ep.seed,
        T_world_objects={name: spec.object_poses(ep.true_object_pose[rows.start], name) for name in spec.objects},
    )


def _check_episode(ep: Episode, index: int, spec: TaskSpec) -> None:
    if ep.task != spec.name:
        raise TaskMismatchError(f"source episode {index} is of task {ep.task!r}, not {spec.name!r}")
    ep.validate(spec)
    poses = np.asarray(ep.true_object_pose, dtype=float)
    quat_norms = np.linalg.norm(poses.reshape(len(poses), -1, 7)[..., 3:], axis=-1)
    if not np.allclose(quat_norms, 1.0, atol=1e-3):
        raise DatasetSchemaError(
            f"source episode {index} (seed {ep.seed}) has no valid true object poses "
            "(complementary_info.true_object_pose); sources must be recorded with igen-collect"
        )
    if not ep.success:
        raise DatasetSchemaError(
            f"source episode {index} (seed {ep.seed}) did not succeed; only successful sources can be replayed"
        )


def _parse(
    episodes: Sequence[Episode],
    spec: TaskSpec,
    target_from_action: TargetFromAction,
    gripper_from_action: GripperFromAction,
    interventions: bool,
) -> SourceLibrary:
    """Cut every checked episode into runs of constant subtask (and, for interventions, actor)."""
    if not episodes:
        raise DatasetSchemaError("the source dataset has no episodes")
    library = SourceLibrary(spec=spec, episodes=len(episodes))
    for index, ep in enumerate(episodes):
        _check_episode(ep, index, spec)
        if interventions and not np.any(ep.is_intervention):
            raise DatasetSchemaError(
                f"source episode {index} (seed {ep.seed}, kind {ep.kind!r}) has no intervention frames "
                "(complementary_info.is_intervention is never set); IntervenGen needs recorded recoveries: "
                "record them with igen-collect --mode=interventions"
            )
        key = ep.subtask * 2 + (ep.is_intervention.astype(np.int64) if interventions else 0)
        for start, end in _runs(key):
            operator = interventions and bool(ep.is_intervention[start])
            if operator and not np.all(ep.source[start:end] != FrameSource.POLICY):
                raise DatasetSchemaError(f"source episode {index}: flagged frames {start}..{end} include policy frames")
            role = (SegmentRole.RECOVERY if operator else SegmentRole.MISTAKE) if interventions else SegmentRole.SUBTASK
            segment = _segment(
                ep,
                index,
                slice(start, end),
                int(ep.subtask[start]),
                role,
                spec,
                target_from_action,
                gripper_from_action,
            )
            library.segments.append(segment)
    return library


def parse_demos(
    episodes: Sequence[Episode],
    spec: TaskSpec,
    target_from_action: TargetFromAction,
    gripper_from_action: GripperFromAction,
) -> SourceLibrary:
    """One :attr:`SegmentRole.SUBTASK` segment per subtask of every demonstration."""
    return _parse(episodes, spec, target_from_action, gripper_from_action, interventions=False)


def parse_interventions(
    episodes: Sequence[Episode],
    spec: TaskSpec,
    target_from_action: TargetFromAction,
    gripper_from_action: GripperFromAction,
) -> SourceLibrary:
    """Mistake (policy) and recovery (operator) segments per subtask of every intervention episode."""
    return _parse(episodes, spec, target_from_action, gripper_from_action, interventions=True)
