"""The one environment protocol the core depends on.

Simulated tasks (``sim/``) implement :class:`TaskEnv`; collection, generation and evaluation
only ever talk to this interface. Privileged methods (true object poses) exist for data
collection and generation only; policies see :meth:`TaskEnv.observe`.

Observation layout, shared by every task (and by ``igen-deploy``):

* ``observation.state``: end-effector position [m], quaternion xyzw, gripper width [m];
* ``observation.environment_state``: the pose (position + quaternion xyzw) of every object as
  the robot believes it, in ``spec.objects`` order; then, for tasks with a reveal contact,
  ``contact`` (the reveal contact happens now) and ``revealed`` (it has happened: latched); then
  the reveal mode's extra values (``direction``: a unit vector, see :mod:`igen_lerobot.core.belief`).
"""

from __future__ import annotations

import abc
import dataclasses
import enum
from dataclasses import dataclass

import numpy as np

from igen_lerobot.core.actions import ActionSpace
from igen_lerobot.core.belief import REVEAL_HINT_NAMES, Reveal

__all__ = [
    "FrameSource",
    "SubtaskSpec",
    "TaskSpec",
    "StepInfo",
    "TaskEnv",
    "OBS_STATE",
    "OBS_ENV_STATE",
    "ACTION",
    "EEF_STATE_NAMES",
    "pose_names",
    "ObjectBox",
]

# LeRobot's feature keys; repeated here so the core does not need torch to import them.
OBS_STATE = "observation.state"
OBS_ENV_STATE = "observation.environment_state"
ACTION = "action"

EEF_STATE_NAMES = ("eef.x", "eef.y", "eef.z", "eef.qx", "eef.qy", "eef.qz", "eef.qw")
SIGNAL_NAMES = ("contact", "revealed")


def pose_names(obj: str) -> tuple[str, ...]:
    """The 7 value names of an object's pose in observations and datasets."""
    return tuple(f"{obj}.{c}" for c in ("x", "y", "z", "qx", "qy", "qz", "qw"))


class FrameSource(enum.IntEnum):
    """Who produced a frame's action (stored per frame in datasets)."""

    POLICY = 0  # the robot policy acting on its (possibly corrupted) observation
    OPERATOR = 1  # a person or the scripted operator
    GENERATED = 2  # a transformed source segment replayed by the generator
    INTERPOLATION = 3  # the generator's bridge from the current pose to a transformed segment


@dataclass(frozen=True)
class SubtaskSpec:
    """One object-centric subtask: its name and the object its motion is relative to."""

    name: str
    object_name: str


@dataclass(frozen=True)
class ObjectBox:
    """How viewers draw an object: a box in the object's frame (half sizes and centre [m])."""

    name: str
    half_size: tuple[float, float, float]
    center: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class TaskSpec:
    """Static description of a configured task: what datasets, generators and policies must agree on.

    ``corrupted_object`` is the object whose observed pose carries the error model's sample, named
    ``corruption_names`` in datasets (e.g. ``peg.dx``). ``reveal_contact`` names the two parts
    whose first contact reveals it (``gripper`` stands for the hand); ``None`` for tasks where
    nothing is revealed (their observation has no contact/revealed values). ``reveal`` is the
    configured reveal mode; it decides the reveal mode's extra observation values.
    """

    name: str
    instruction: str
    robot_type: str
    fps: int
    max_episode_steps: int
    objects: tuple[str, ...]
    subtasks: tuple[SubtaskSpec, ...]
    action_names: tuple[str, ...]
    corrupted_object: str
    corruption_names: tuple[str, ...]
    reveal_contact: tuple[str, str] | None = None
    reveal: Reveal = Reveal.FULL
    state_names: tuple[str, ...] = (*EEF_STATE_NAMES, "gripper.width")
    env_state_names: tuple[str, ...] = ()  # () = the standard layout (see the module docstring)
    boxes: tuple[ObjectBox, ...] = ()  # how to draw each object (default: a 5 cm cube)
    # cameras the task renders (a simulated task has at least a fixed third-person "agentview" and a "wrist")
    cameras: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "reveal", Reveal(self.reveal))
        if tuple(self.state_names[:7]) != EEF_STATE_NAMES:
            raise ValueError(f"task {self.name!r}: state_names must start with {EEF_STATE_NAMES}")
        for sub in self.subtasks:
            if sub.object_name not in self.objects:
                raise ValueError(
                    f"task {self.name!r}: subtask {sub.name!r} refers to unknown object {sub.object_name!r}"
                )
        if self.corrupted_object not in self.objects:
            raise ValueError(f"task {self.name!r}: corrupted_object {self.corrupted_object!r} is not in {self.objects}")
        prefix = f"{self.corrupted_object}."
        if not self.corruption_names or not all(n.startswith(prefix) for n in self.corruption_names):
            raise ValueError(f"task {self.name!r}: corruption_names must all start with {prefix!r}")
        if self.reveal_contact is None and self.reveal is not Reveal.NONE:
            raise ValueError(f"task {self.name!r} has no reveal contact, so its reveal mode can only be 'none'")
        expected = self.standard_env_state_names()
        if not self.env_state_names:
            object.__setattr__(self, "env_state_names", expected)
        elif tuple(self.env_state_names) != expected:
            raise ValueError(f"task {self.name!r}: env_state_names must be the standard layout {expected}")

    def standard_env_state_names(self) -> tuple[str, ...]:
        names = [n for obj in self.objects for n in pose_names(obj)]
        if self.reveal_contact is not None:
            names += SIGNAL_NAMES
        names += [f"{self.corrupted_object}.{h}" for h in REVEAL_HINT_NAMES.get(self.reveal, ())]
        return tuple(names)

    def with_reveal(self, reveal: Reveal) -> TaskSpec:
        """The same task under another reveal mode (its observation layout may change)."""
        return dataclasses.replace(self, reveal=Reveal(reveal), env_state_names=())

    def with_corruption_names(self, names: tuple[str, ...]) -> TaskSpec:
        """The same task with another error model's value names (``dx`` -> ``<object>.dx``)."""
        return dataclasses.replace(self, corruption_names=tuple(f"{self.corrupted_object}.{n}" for n in names))

    @property
    def error_value_names(self) -> tuple[str, ...]:
        """``corruption_names`` without the object prefix: what the error model calls them."""
        return tuple(n.split(".", 1)[1] for n in self.corruption_names)

    def box(self, obj: str) -> ObjectBox:
        """The drawing box of ``obj``."""
        return next((b for b in self.boxes if b.name == obj), ObjectBox(obj, (0.025, 0.025, 0.025)))

    def revealed_flags(self, env_state: np.ndarray) -> np.ndarray:
        """The latched ``revealed`` value of each ``observation.environment_state`` row (False without one)."""
        env_state = np.asarray(env_state)
        if "revealed" not in self.env_state_names:
            return np.zeros(len(env_state), dtype=bool)
        return env_state[:, self.env_state_names.index("revealed")] > 0.5

    def env_state_index(self, name: str) -> int:
        """Position of a named value in ``observation.environment_state``."""
        return self.env_state_names.index(name)

    def eef_poses(self, state: np.ndarray) -> np.ndarray:
        """``T_world_eef`` (N, 4, 4) from ``observation.state`` rows (N, S)."""
        from igen_lerobot.core.geometry import pos_quat_to_pose

        state = np.asarray(state, dtype=float)
        return pos_quat_to_pose(state[..., :3], state[..., 3:7])

    def object_poses(self, true_object_pose: np.ndarray, name: str) -> np.ndarray:
        """``T_world_obj`` (N, 4, 4) of object ``name`` from ``complementary_info.true_object_pose`` rows."""
        from igen_lerobot.core.geometry import pos_quat_to_pose

        k = self.objects.index(name)
        rows = np.asarray(true_object_pose, dtype=float)[..., 7 * k : 7 * k + 7]
        return pos_quat_to_pose(rows[..., :3], rows[..., 3:7])

    @property
    def object_pose_names(self) -> tuple[str, ...]:
        """Names of the flattened true object poses (position [m] + quaternion xyzw per object)."""
        return tuple(n for obj in self.objects for n in pose_names(obj))


@dataclass(frozen=True)
class StepInfo:
    """What happened during one control step."""

    contact: bool  # the task's reveal contact happens now (e.g. nut touches peg)
    revealed: bool  # the corrupted pose has been (at least partly) revealed to the robot
    success: bool  # the whole task is done
    mistake: bool = False  # the task's mistake signal fired on this step (what a takeover reacts to)


class TaskEnv(abc.ABC):
    """A task the generator can reset, observe, step and judge.

    Actions are the task's own (``spec.action_names``, ``action_space``); :meth:`action_towards`
    turns a target end-effector pose into one, which is how transformed segments are replayed.
    """

    spec: TaskSpec
    action_space: ActionSpace

    @abc.abstractmethod
    def reset(self, seed: int, corruption: np.ndarray | None = None) -> dict[str, np.ndarray]:
        """New scene from ``seed``; ``corruption`` overrides the sampled error (replay)."""

    @abc.abstractmethod
    def observe(self) -> dict[str, np.ndarray]:
        """The robot's observation: ``observation.state`` and ``observation.environment_state``."""

    @abc.abstractmethod
    def step(self, action: np.ndarray) -> StepInfo:
        """Apply one action for one control period (1 / fps s)."""

    @abc.abstractmethod
    def eef_pose(self) -> np.ndarray:
        """``T_world_eef`` (4x4) of the controlled end effector."""

    @abc.abstractmethod
    def gripper_width(self) -> float:
        """Distance between the fingers [m]."""

    @abc.abstractmethod
    def true_object_poses(self) -> dict[str, np.ndarray]:
        """Privileged ``T_world_obj`` per object (collection and generation only)."""

    @abc.abstractmethod
    def believed_object_poses(self) -> dict[str, np.ndarray]:
        """``T_world_obj`` per object as the robot currently believes it."""

    @abc.abstractmethod
    def subtask_index(self) -> int:
        """Index of the first subtask not yet done (``len(spec.subtasks)`` once all are)."""

    @abc.abstractmethod
    def is_success(self) -> bool:
        """Whether the task is complete in the current state."""

    @property
    @abc.abstractmethod
    def corruption(self) -> np.ndarray:
        """The current episode's error sample, named like ``spec.corruption_names``."""

    @property
    @abc.abstractmethod
    def revealed(self) -> bool:
        """Whether the reveal contact has happened in this episode."""

    def revealing_parts(self) -> tuple[str, str] | None:
        """The two parts whose contact revealed the corrupted object in this episode (None before it).

        Names as in ``spec.reveal_contact`` (objects, or ``gripper``); tests and logs use it to check
        that the reveal came from the declared contact.
        """
        return None

    def budget_forces_recovery(self, subtask: int) -> bool:
        """Whether running out IntervenGen's mistake budget in ``subtask`` counts as a mistake.

        A policy that ran the budget without a signalled mistake is then given a recovery.
        Default: every subtask. A task whose policy may need longer than the budget to do a subtask
        right says no there and signals that subtask's mistakes itself (Nut-and-Peg's place: a place
        that succeeds holds the nut longer than the budget; a stalled one is a signalled mistake);
        the policy then runs on to a mistake, success, the next subtask or the attempt's step limit.
        """
        return True

    def recovery_done(self, subtask: int) -> bool:
        """Whether a replayed recovery of ``subtask`` may hand control back to the policy now.

        Asked while the recovery holds its last goal, after its recorded frames. Default: once the
        subtask is done. A task whose policy needs more (Nut-and-Peg: a grasp settled for a few
        steps, not the first touch of the pads) says so here.
        """
        return self.subtask_index() > subtask

    def replay_goals(
        self,
        goals: np.ndarray,
        subtask: int,
        T_src_world_objects: dict[str, np.ndarray],
        T_src_world_eef: np.ndarray,
    ) -> np.ndarray:
        """A source segment's end-effector goals, already moved into this scene, as the task replays them.

        ``goals`` (N, 4, 4); ``T_src_world_objects`` and ``T_src_world_eef`` are the source's true
        object poses and end effector at the segment's first frame. Default: unchanged. A task
        whose hand is symmetric under a half turn (a parallel gripper) may take the equivalent
        goals that start nearer the hand, or that keep a held object on the source's side of it
        (Nut-and-Peg).
        """
        return goals

    def bridge_waypoint(self, subtask: int) -> np.ndarray | None:
        """A pose (4, 4) the bridge to a replayed segment of ``subtask`` passes through first, or None.

        Default None: the bridge goes straight from the hand to the segment's first goal. A task whose
        hand may hold an object low beside an obstacle says where to go first (Nut-and-Peg: a place
        replayed with the nut stalled beside the peg lifts it clear of the peg's top before moving over).
        """
        return None

    def action_towards(self, T_world_eef_target: np.ndarray, gripper_closed: bool) -> np.ndarray:
        """The action that drives the end effector towards a target pose in one step."""
        return self.action_space.action_towards(self.eef_pose(), T_world_eef_target, gripper_closed)

    def gripper_command(self, action: np.ndarray) -> bool:
        """Whether ``action`` commands the gripper closed."""
        return self.action_space.gripper_closed(action)

    def target_pose_from_action(self, T_world_eef: np.ndarray, action: np.ndarray) -> np.ndarray:
        """The end-effector goal ``action`` sets when taken at ``T_world_eef``.

        The inverse of :meth:`action_towards`: what the generator transforms when it moves a
        recorded segment into a new scene.
        """
        return self.action_space.target_pose(T_world_eef, action)

    def action_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Per-dimension action limits the env clips to."""
        return self.action_space.bounds()

    def true_object_pose_vector(self) -> np.ndarray:
        """True object poses flattened like ``spec.object_pose_names`` (position + quat xyzw)."""
        from igen_lerobot.core.geometry import pose_vector

        poses = self.true_object_poses()
        return np.concatenate([pose_vector(poses[name]) for name in self.spec.objects])

    # ------------------------------------------------------------------ simulator state
    def sim_state(self) -> np.ndarray | None:
        """Everything needed to restore this instant exactly (float64), or None where there is no simulator.

        Recorded on every frame so a dataset can be re-rendered later with any camera.
        """
        return None

    def sim_state_layout(self) -> dict | None:
        """What a :meth:`sim_state` vector holds (stored with the dataset; restoring checks it matches)."""
        return None

    def restore_sim_state(self, state: np.ndarray) -> None:
        """Put the simulator back into a recorded :meth:`sim_state`."""
        raise NotImplementedError(f"task {self.spec.name!r} has no simulator state to restore")

    def render(self, camera: str, width: int, height: int) -> np.ndarray:
        """(height, width, 3) uint8 RGB from one of ``spec.cameras``."""
        raise NotImplementedError(f"task {self.spec.name!r} renders no cameras")

    def close(self) -> None:  # noqa: B027 - optional hook, most envs hold no resources.
        """Release simulator or hardware resources."""
