"""A numpy-only task with two subtasks and rotated objects, for testing the core without MuJoCo.

"Pick and place": a kinematic hand (it reaches each step's goal exactly) grasps a block lying at a
random position and yaw, and places it on a pad at another random position and yaw. Subtask 0
(grasp) is relative to the block, subtask 1 (place) to the pad. The block's observed position is
off by the error model's sample until the fingers land on it (the reveal contact, and the
mistake), exactly like the simulated tasks; the scripted operator and policy follow one Markov
rule on the true and the believed block. Being exact and fast, it shows the generator's subtask
loop and its SE(3) transforms (rotations included) working end to end.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from lerobot.envs.configs import EnvConfig

from igen_lerobot.core.actions import DeltaPoseActions
from igen_lerobot.core.agents import Operator
from igen_lerobot.core.belief import ObjectBelief, Reveal
from igen_lerobot.core.env_config import TaskEnvConfig, register_gym_env
from igen_lerobot.core.error_models import BoxNoise, ErrorModel
from igen_lerobot.core.geometry import make_pose, pos_quat_to_pose, rot_z
from igen_lerobot.core.observation import observation
from igen_lerobot.core.paper import PaperTable
from igen_lerobot.core.task import OBS_ENV_STATE, OBS_STATE, ObjectBox, StepInfo, SubtaskSpec, TaskEnv, TaskSpec

TOP_DOWN = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])
BLOCK_HALF = 0.02  # [m]
OPEN_WIDTH, HELD_WIDTH = 0.08, 2 * BLOCK_HALF
GRASP_TOL_XY, GRASP_TOL_Z, GRASP_TOL_YAW = 0.01, 0.01, np.deg2rad(10)
PLACE_TOL_XY, PLACE_TOL_YAW = 0.015, np.deg2rad(10)
FINGER_REACH = 0.045  # [m] a finger lands on the block when the hand is this close to it but not aligned
HOME = make_pose((0.0, 0.0, 0.25), TOP_DOWN)

SPEC = TaskSpec(
    name="fake_pick_place",
    instruction="Put the block on the pad.",
    robot_type="kinematic_hand",
    fps=20,
    max_episode_steps=200,
    objects=("block", "pad"),
    subtasks=(SubtaskSpec("grasp", "block"), SubtaskSpec("place", "pad")),
    action_names=DeltaPoseActions().names,
    corrupted_object="block",
    corruption_names=("block.dx", "block.dy", "block.dz"),
    reveal_contact=("gripper", "block"),
    boxes=(ObjectBox("block", (BLOCK_HALF,) * 3), ObjectBox("pad", (0.03, 0.03, 0.002))),
)


def yaw_of(rot: np.ndarray) -> float:
    return float(np.arctan2(rot[1, 0], rot[0, 0]))


def yaw_gap(a: float, b: float, period: float) -> float:
    """Smallest difference of two yaws [rad] modulo ``period``."""
    d = (a - b) % period
    return float(min(d, period - d))


def grasp_pose(T_world_obj: np.ndarray, height: float) -> np.ndarray:
    """A top-down hand over the object's centre, fingers across the object's y axis, at ``height`` above it."""
    return make_pose(T_world_obj[:3, 3] + (0.0, 0.0, height), rot_z(yaw_of(T_world_obj[:3, :3])) @ TOP_DOWN)


class FakePickPlaceEnv(TaskEnv):
    """Kinematic pick-and-place; every pose is exact, nothing is simulated but geometry."""

    spec = SPEC

    def __init__(self, corruption: ErrorModel | None = None, reveal: Reveal = Reveal.FULL) -> None:
        self.spec = SPEC.with_reveal(reveal)
        self.action_space = DeltaPoseActions(max_delta=0.03, max_rotation=0.2)
        self.error_model = corruption if corruption is not None else BoxNoise((0.03, 0.03, 0.0), (0.02, 0.02, 0.0))
        self.belief = ObjectBelief(self.error_model, np.zeros(len(self.error_model.names)), self.spec.reveal)
        self.reset(0)

    def reset(self, seed: int, corruption: np.ndarray | None = None) -> dict[str, np.ndarray]:
        rng = np.random.default_rng(seed)
        self.T_eef = HOME.copy()
        self.closed = False
        self.held: np.ndarray | None = None  # T_eef_block while the block is in the hand
        block_xy = rng.uniform(-0.1, 0.1, 2) + (0.0, -0.15)
        pad_xy = rng.uniform(-0.1, 0.1, 2) + (0.0, 0.15)
        self.T_block = make_pose((*block_xy, BLOCK_HALF), rot_z(rng.uniform(-np.pi, np.pi)))
        self.T_pad = make_pose((*pad_xy, 0.0), rot_z(rng.uniform(-np.pi, np.pi)))
        sample = self.error_model.sample(rng) if corruption is None else self.error_model.checked(corruption)
        self.belief = ObjectBelief(self.error_model, sample, self.spec.reveal)
        return self.observe()

    def _landed_on_block(self) -> bool:
        offset = np.linalg.norm(self.T_eef[:2, 3] - self.T_block[:2, 3])
        low = self.T_eef[2, 3] < self.T_block[2, 3] + BLOCK_HALF
        return bool(self.held is None and low and GRASP_TOL_XY < offset < FINGER_REACH)

    def step(self, action: np.ndarray) -> StepInfo:
        action = self.action_space.checked(action, self.spec.name)
        target = self.action_space.target_pose(self.T_eef, action)
        target[2, 3] = max(target[2, 3], BLOCK_HALF)  # the table
        self.T_eef = target
        contact = self._landed_on_block()
        if contact:  # a finger rests on the block's top
            self.T_eef[2, 3] = self.T_block[2, 3] + BLOCK_HALF
        close = self.action_space.gripper_closed(action)
        if close and not self.closed and self.held is None and self._can_grasp():
            self.held = np.linalg.inv(self.T_eef) @ self.T_block
        if not close and self.held is not None:  # let go: the block drops onto the table
            self.T_block = make_pose((*self.T_block[:2, 3], BLOCK_HALF), rot_z(yaw_of(self.T_block[:3, :3])))
            self.held = None
        self.closed = close
        if self.held is not None:
            self.T_block = self.T_eef @ self.held
        revealed_now = self.belief.update(contact, self.T_eef[:3, 3], self.T_block)
        return StepInfo(contact, self.belief.revealed, self.is_success(), revealed_now)

    def _can_grasp(self) -> bool:
        gap = self.T_eef[:3, 3] - self.T_block[:3, 3]
        yaw = yaw_gap(hand_yaw(self.T_eef), yaw_of(self.T_block[:3, :3]), np.pi / 2)
        return bool(np.linalg.norm(gap[:2]) < GRASP_TOL_XY and abs(gap[2]) < GRASP_TOL_Z and yaw < GRASP_TOL_YAW)

    def observe(self) -> dict[str, np.ndarray]:
        return observation(self.spec, self.T_eef, self.gripper_width(), self.believed_object_poses(), self.belief)

    def eef_pose(self) -> np.ndarray:
        return self.T_eef.copy()

    def gripper_width(self) -> float:
        if not self.closed:
            return OPEN_WIDTH
        return HELD_WIDTH if self.held is not None else 0.0

    def true_object_poses(self) -> dict[str, np.ndarray]:
        return {"block": self.T_block.copy(), "pad": self.T_pad.copy()}

    def believed_object_poses(self) -> dict[str, np.ndarray]:
        poses = self.true_object_poses()
        poses["block"] = self.belief.believed_pose(poses["block"])
        return poses

    def on_pad(self) -> bool:
        """The block lies on the pad, let go of."""
        gap = np.linalg.norm(self.T_block[:2, 3] - self.T_pad[:2, 3])
        yaw = yaw_gap(yaw_of(self.T_block[:3, :3]), yaw_of(self.T_pad[:3, :3]), np.pi / 2)
        return bool(self.held is None and gap < PLACE_TOL_XY and yaw < PLACE_TOL_YAW)

    def placed(self) -> bool:
        return self.on_pad() and self.T_eef[2, 3] > 0.06  # and the hand is clear of it

    def subtask_index(self) -> int:
        if self.is_success():
            return 2
        return 1 if self.held is not None or self.on_pad() else 0

    def is_success(self) -> bool:
        return self.placed()

    def revealing_parts(self) -> tuple[str, str] | None:
        return ("gripper", "block") if self.belief.revealed else None

    @property
    def corruption(self) -> np.ndarray:
        return self.belief.sample.copy()

    @property
    def revealed(self) -> bool:
        return self.belief.revealed

    @property
    def contact(self) -> bool:
        return self.belief.contact


def hand_yaw(T_eef: np.ndarray) -> float:
    """Yaw of a top-down hand (its rotation is ``rot_z(yaw) @ TOP_DOWN``)."""
    return yaw_of(T_eef[:3, :3] @ TOP_DOWN.T)


def nearest_yaw(target: float, current: float, period: float) -> float:
    """``target`` plus the multiple of ``period`` closest to ``current`` (a square's symmetric yaws)."""
    return target + period * round((current - target) / period)


@dataclass(frozen=True)
class PickPlaceRule:
    """Hover, align, descend, close; carry, align, descend, open, rise (distances [m], speeds per step)."""

    hover: float = 0.1
    speed: float = 0.025

    def act(self, T_eef: np.ndarray, width: float, T_block: np.ndarray, T_pad: np.ndarray) -> tuple[np.ndarray, bool]:
        rise = make_pose(T_eef[:3, 3] + (0.0, 0.0, self.speed), T_eef[:3, :3])
        if width < 0.5 * HELD_WIDTH:  # closed on air: open and rise
            return rise, False
        holding = width < 0.5 * (HELD_WIDTH + OPEN_WIDTH)
        if not holding and np.linalg.norm(T_block[:2, 3] - T_pad[:2, 3]) < PLACE_TOL_XY and T_block[2, 3] < 0.03:
            return rise, False  # placed: move away
        if holding:  # put the block (not the hand) onto the pad, at the pad's nearest symmetric yaw
            block_yaw = yaw_of(T_block[:3, :3])
            goal = make_pose(
                (*T_pad[:2, 3], BLOCK_HALF), rot_z(nearest_yaw(yaw_of(T_pad[:3, :3]), block_yaw, np.pi / 2))
            )
            at = goal @ np.linalg.inv(np.linalg.inv(T_eef) @ T_block)
        else:  # grasp across the block's nearest face
            yaw = nearest_yaw(yaw_of(T_block[:3, :3]), hand_yaw(T_eef), np.pi / 2)
            at = make_pose(T_block[:3, 3], rot_z(yaw) @ TOP_DOWN)
        above = at.copy()
        above[2, 3] += self.hover
        aligned = np.linalg.norm(T_eef[:2, 3] - above[:2, 3]) < 0.003 and _angle(T_eef, above) < np.deg2rad(2)
        if not aligned:
            if T_eef[2, 3] < above[2, 3] - 0.03:
                return rise, holding
            return self._to(T_eef, above), holding
        if T_eef[2, 3] - at[2, 3] > 0.002:
            return self._to(T_eef, at), holding
        return at, not holding  # at the block: close; at the pad: open

    def _to(self, T_eef: np.ndarray, target: np.ndarray) -> np.ndarray:
        delta = target[:3, 3] - T_eef[:3, 3]
        norm = float(np.linalg.norm(delta))
        goal = target.copy()
        if norm > self.speed:
            goal[:3, 3] = T_eef[:3, 3] + delta * self.speed / norm
        return goal


def _angle(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.arccos(np.clip((np.trace(a[:3, :3].T @ b[:3, :3]) - 1) / 2, -1, 1)))


class FakePolicy:
    """The rule on the believed block (trusts its observation)."""

    def __init__(self) -> None:
        self.rule, self.actions = PickPlaceRule(), DeltaPoseActions(max_delta=0.03, max_rotation=0.2)

    def reset(self) -> None:
        """Stateless."""

    def act(self, obs: dict[str, np.ndarray]) -> np.ndarray:
        state, env_state = np.asarray(obs[OBS_STATE], float), np.asarray(obs[OBS_ENV_STATE], float)
        T_eef = pos_quat_to_pose(state[:3], state[3:7])
        T_block = pos_quat_to_pose(env_state[:3], env_state[3:7])
        T_pad = pos_quat_to_pose(env_state[7:10], env_state[10:14])
        goal, close = self.rule.act(T_eef, float(state[7]), T_block, T_pad)
        return self.actions.action_towards(T_eef, goal, close)


class FakeOperator(Operator):
    """The rule on the true block; takes over on the first finger-on-block contact."""

    def __init__(self) -> None:
        self.rule = PickPlaceRule()

    def wants_control(self, env: TaskEnv, in_control: bool) -> bool:
        return in_control or bool(env.contact)

    def act(self, env: TaskEnv) -> np.ndarray:
        poses = env.true_object_poses()
        goal, close = self.rule.act(env.eef_pose(), env.gripper_width(), poses["block"], poses["pad"])
        return env.action_towards(goal, close)


@EnvConfig.register_subclass("fake_pick_place")
@dataclass
class FakePickPlaceConfig(TaskEnvConfig):
    """The fake task as an igen task config (registered only where the tests import it)."""

    base_spec = SPEC
    paper_tables = (PaperTable(Reveal.FULL, rows=("base", "igen")),)

    task: str | None = "FakePickPlace-v0"
    fps: int = 20
    corruption: ErrorModel = field(default_factory=lambda: BoxNoise((0.03, 0.03, 0.0), (0.02, 0.02, 0.0)))

    def make_action_space(self) -> DeltaPoseActions:
        return DeltaPoseActions(max_delta=0.03, max_rotation=0.2)

    def make_task_env(self) -> TaskEnv:
        return FakePickPlaceEnv(self.corruption, self.reveal)

    def make_scripted_operator(self) -> Operator:
        return FakeOperator()

    def make_scripted_policy(self) -> FakePolicy:
        return FakePolicy()


register_gym_env(FakePickPlaceConfig)
