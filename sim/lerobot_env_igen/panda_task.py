"""What every simulated task shares: a Panda at a table, objects, the belief, the action space.

A task's env is built from its config (:class:`~lerobot_env_igen.config_panda_task.PandaTaskEnvConfig`:
spec, action space, error model); it supplies its scene objects, how a seed places them
(:meth:`PandaTaskEnv.place`, usually a :class:`~lerobot_env_igen.placement.RegionPlacer` handed the
reset's generator), its success test and, if it differs from the default, its mistake signal and
subtask progress. The base does the rest the same way for every task: one compiled model whose
free objects are set through their joints and fixed ones (peg, receptacle, holder) through
``model.body_pos`` at reset, 6-DOF or position-only actions at 20 Hz, contact detection between
any two named parts, the core's :class:`~igen_lerobot.core.belief.ObjectBelief` for the corrupted
object, and the observation layout of :mod:`igen_lerobot.core.task`.
"""

from __future__ import annotations

import abc
import logging
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from igen_lerobot.core.belief import ObjectBelief, Reveal
from igen_lerobot.core.observation import observation
from igen_lerobot.core.task import StepInfo, TaskEnv
from lerobot_env_igen.arm_randomization import NO_DRAW, ArmDraw, rotation_noise
from lerobot_env_igen.cameras import PANDA_CAMERAS
from lerobot_env_igen.panda import TOP_DOWN_ROT, ContactEvent, PandaArm
from lerobot_env_igen.panda_spec import GRIPPER
from lerobot_env_igen.scene import build_panda_table_scene

if TYPE_CHECKING:
    from lerobot_env_igen.config_panda_task import PandaTaskEnvConfig

logger = logging.getLogger(__name__)

__all__ = ["PandaTaskEnv", "GRIPPER"]


class PandaTaskEnv(TaskEnv):
    """A task on the compiled robosuite Panda scene."""

    def __init__(
        self,
        config: PandaTaskEnvConfig,
        objects: list,
        home_pos: tuple[float, float, float],
        home_rot: np.ndarray = TOP_DOWN_ROT,
    ) -> None:
        """``objects``: the scene's robosuite objects; ``home_pos`` [m]: where the grip site starts."""
        spec, action_space = config.task_spec, config.make_action_space()
        if tuple(action_space.names) != tuple(spec.action_names):
            raise ValueError(f"task {spec.name!r}: action space {action_space.names} != spec {spec.action_names}")
        self.spec = spec
        self.action_space = action_space
        self.error_model = config.corruption
        self.randomization = config.randomize
        self.arm_draw: ArmDraw = NO_DRAW  # this episode's arm (reset draws it from the seed)
        self._obs_noise: np.random.Generator | None = None
        self._object_noise: np.random.Generator | None = None
        self.max_delta = float(config.max_delta)
        model, default_qpos = build_panda_table_scene(objects)
        home = np.asarray(home_pos, dtype=float)
        self.arm = PandaArm(model, default_qpos, home, control_hz=spec.fps, home_rot=home_rot)
        self.model, self.data = model, self.arm.data
        # each object's root body: ``<name>_main`` for robosuite's primitives and XML objects, ``<name>_root``
        # for its composite objects (a ``Bin``)
        roots = {obj.name: obj.root_body for obj in objects}
        self.bodies = {name: self._body(roots.get(name, f"{name}_main")) for name in spec.objects}
        self.part_masks = {name: self.arm.geom_mask(self.collision_geoms(body)) for name, body in self.bodies.items()}
        self.part_masks[GRIPPER] = self.arm.gripper_geom_mask
        pads = (self.arm.names.left_pad, self.arm.names.right_pad)
        self._pad_ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, n) for n in pads]
        self._pad_mask = self.arm.geom_mask(self._pad_ids)
        self._free_qpos = {
            name: model.jnt_qposadr[model.body_jntadr[body]]
            for name, body in self.bodies.items()
            if model.body_jntnum[body] > 0
        }
        self._reveal_watch = None
        if spec.reveal_contact is not None:
            self._reveal_watch = tuple(self.part_masks[p] for p in spec.reveal_contact)
        self.belief = ObjectBelief(self.error_model, self.error_model.sample(np.random.default_rng(0)), spec.reveal)
        self.last_reveal_contact: ContactEvent | None = None  # the contact that revealed, for tests and logs
        self._steps = 0
        self._renderer: mujoco.Renderer | None = None
        self._render_option = mujoco.MjvOption()
        self._render_option.sitegroup[:] = 0  # hide robosuite's helper sites (grip axis, frames)

    # ------------------------------------------------------------------ model lookups
    def _body(self, name: str) -> int:
        body = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, name)
        if body < 0:
            raise ValueError(f"task {self.spec.name!r}: the scene has no body {name!r}")
        return body

    def collision_geoms(self, body: int) -> list[int]:
        """Geoms of ``body`` that collide (robosuite's ``_visual`` copies do not)."""
        model = self.model
        return [g for g in range(model.ngeom) if model.geom_bodyid[g] == body and model.geom_contype[g]]

    def body_pose(self, body: int) -> np.ndarray:
        pose = np.zeros((4, 4))
        pose[:3, :3] = self.data.xmat[body].reshape(3, 3)
        pose[:3, 3] = self.data.xpos[body]
        pose[3, 3] = 1.0
        return pose

    def set_free_pose(self, name: str, pos: np.ndarray, quat_wxyz: np.ndarray = (1.0, 0.0, 0.0, 0.0)) -> None:
        """Place a free object (position [m], MuJoCo quaternion), at rest."""
        adr = self._free_qpos[name]
        self.data.qpos[adr : adr + 3] = pos
        self.data.qpos[adr + 3 : adr + 7] = quat_wxyz
        dof = self.model.jnt_dofadr[self.model.body_jntadr[self.bodies[name]]]
        self.data.qvel[dof : dof + 6] = 0.0

    def set_fixed_pose(self, name: str, pos: np.ndarray, quat_wxyz: np.ndarray = (1.0, 0.0, 0.0, 0.0)) -> None:
        """Move a fixed body (no recompiling: its pose lives in ``model.body_pos``/``body_quat``)."""
        body = self.bodies[name]
        self.model.body_pos[body] = pos
        self.model.body_quat[body] = quat_wxyz

    def set_pose(self, name: str, pos: np.ndarray, quat_wxyz: np.ndarray = (1.0, 0.0, 0.0, 0.0)) -> None:
        """Place an object, free or fixed (what a :class:`~lerobot_env_igen.placement.RegionPlacer` calls)."""
        if name in self._free_qpos:
            self.set_free_pose(name, pos, quat_wxyz)
        else:
            self.set_fixed_pose(name, pos, quat_wxyz)

    def part_of_geom(self, geom: int) -> str | None:
        """Which named part (an object or ``gripper``) a geom belongs to."""
        return next((name for name, mask in self.part_masks.items() if mask[geom]), None)

    def revealing_parts(self) -> tuple[str, str] | None:
        if self.last_reveal_contact is None:
            return None
        g1, g2 = self.last_reveal_contact.geom_pairs[0]
        return self.part_of_geom(int(g1)), self.part_of_geom(int(g2))

    def parts_in_contact(self, a: str, b: str) -> bool:
        """Whether two named parts (objects or ``gripper``) touch now."""
        return self.arm.in_contact(self.part_masks[a], self.part_masks[b])

    def held_by_both_pads(self, part: str) -> bool:
        """Both finger pads touch ``part`` now: a grasp, not one finger brushing it."""
        mask, touching = self.part_masks[part], set()
        for g1, g2 in self.data.contact.geom[: self.data.ncon]:
            if mask[g1] and self._pad_mask[g2]:
                touching.add(int(g2))
            elif mask[g2] and self._pad_mask[g1]:
                touching.add(int(g1))
        return len(touching) == len(self._pad_ids)

    # ------------------------------------------------------------------ task hooks
    @abc.abstractmethod
    def place(self, rng: np.random.Generator) -> None:
        """Lay out a new scene from ``rng`` (the arm is at home, fingers open, nothing moving yet)."""

    @abc.abstractmethod
    def is_success(self) -> bool:
        """The task's success test on the current state."""

    def settle(self) -> None:
        """Run after placing and before the first observation (e.g. let a held object settle)."""

    def mistake(self, revealed_now: bool, close_gripper: bool) -> bool:
        """The task's mistake signal for this step: by default the contact that reveals."""
        return revealed_now

    def subtask_index(self) -> int:
        return len(self.spec.subtasks) if self.is_success() else 0

    # ------------------------------------------------------------------ episode
    def reset(self, seed: int, corruption: np.ndarray | None = None) -> dict[str, np.ndarray]:
        rng = np.random.default_rng(seed)
        self._apply_arm_draw(self.randomization.draw(seed))
        self.arm.reset()
        self.place(rng)
        mujoco.mj_forward(self.model, self.data)
        sampled = self.error_model.sample(rng)
        sample = sampled if corruption is None else self.error_model.checked(corruption, "corruption override")
        self.belief = ObjectBelief(self.error_model, sample, self.spec.reveal)
        self.last_reveal_contact = None
        self.settle()
        self._steps = 0
        return self.observe()

    def _apply_arm_draw(self, draw: ArmDraw) -> None:
        self.arm_draw = draw
        self.arm.set_dynamics(draw.kp_scale, draw.latency)
        self._obs_noise = np.random.default_rng(draw.noise_seed) if draw.eef_pos_noise else None
        # a stream of its own: the hand's noise stays what it was without the objects'
        self._object_noise = np.random.default_rng((draw.noise_seed, 1)) if draw.object_rot_noise else None

    def step(self, action: np.ndarray) -> StepInfo:
        action = self.action_space.checked(action, self.spec.name)
        target = self.action_space.target_pose(self.eef_pose(), action)
        # a randomised hand tilt only reaches position-only tasks (the config refuses it elsewhere)
        goal_rot = self.arm_draw.tilt @ target[:3, :3] if self.randomization.hand_tilt_deg else target[:3, :3]
        return self.step_to(target[:3, 3], self.action_space.gripper_closed(action), goal_rot=goal_rot)

    def step_to(
        self,
        goal_pos: np.ndarray,
        close_gripper: bool,
        measure_force: bool = False,
        goal_rot: np.ndarray | None = None,
    ) -> StepInfo:
        """One control period towards an absolute end-effector goal (a driver's Cartesian target).

        ``goal_rot`` None keeps the last goal orientation. With ``measure_force`` the arm records
        the period's peak contact force on the gripper (``self.arm.peak_contact_force``), the
        simulated counterpart of a real arm's estimate.
        """
        event = self.arm.control_period(
            np.asarray(goal_pos, dtype=float), close_gripper, goal_rot, self._reveal_watch, measure_force
        )
        self._steps += 1
        revealed_now = False
        if self._reveal_watch is not None:
            # the true pose matters only to the contact that reveals: skip it on every other step
            reveals = event is not None and not self.belief.revealed
            T_true = self.body_pose(self.bodies[self.spec.corrupted_object]) if reveals else None
            revealed_now = self.belief.update(event is not None, None if event is None else event.position, T_true)
            if revealed_now:
                self.last_reveal_contact = event
                logger.debug("%s revealed at step %d (%s)", self.spec.corrupted_object, self._steps, self.spec.reveal)
        return StepInfo(
            contact=event is not None,
            revealed=self.belief.revealed,
            success=self.is_success(),
            mistake=self.mistake(revealed_now, close_gripper),
        )

    # ------------------------------------------------------------------ observation
    def observe(self) -> dict[str, np.ndarray]:
        T_world_eef = self.eef_pose()
        if self._obs_noise is not None:  # the policy sees the hand where a noisy estimate puts it
            T_world_eef[:3, 3] += self._obs_noise.normal(0.0, self.arm_draw.eef_pos_noise, 3)
        poses = self.believed_object_poses()
        if self._object_noise is not None:  # the policy sees the objects turned as a camera's estimate turns them
            for name in self.spec.objects:
                turn = rotation_noise(self._object_noise, self.arm_draw.object_rot_noise)
                poses[name][:3, :3] = turn @ poses[name][:3, :3]
        return observation(self.spec, T_world_eef, self.gripper_width(), poses, self.belief)

    def true_object_poses(self) -> dict[str, np.ndarray]:
        return {name: self.body_pose(body) for name, body in self.bodies.items()}

    def true_object_pose_vector(self) -> np.ndarray:
        # recorded on every frame: MuJoCo's body quaternions, not a conversion from matrices
        out = np.empty(7 * len(self.bodies))
        for k, body in enumerate(self.bodies.values()):
            quat = self.data.xquat[body]
            out[7 * k : 7 * k + 3] = self.data.xpos[body]
            out[7 * k + 3 : 7 * k + 7] = (quat[1], quat[2], quat[3], quat[0])
        return out

    def believed_object_poses(self) -> dict[str, np.ndarray]:
        poses = self.true_object_poses()
        obj = self.spec.corrupted_object
        poses[obj] = self.belief.believed_pose(poses[obj])
        return poses

    def eef_pose(self) -> np.ndarray:
        return self.arm.eef_pose()

    def wrist_joint(self) -> tuple[float, float, float]:
        """The last arm joint's (the wrist's turn about the hand's axis) angle and range [rad]."""
        address = self.arm.arm_qpos[-1]
        joint = int(np.flatnonzero(self.model.jnt_qposadr == address)[0])
        low, high = self.model.jnt_range[joint]
        return float(self.data.qpos[address]), float(low), float(high)

    def gripper_width(self) -> float:
        return self.arm.gripper_width()

    @property
    def corruption(self) -> np.ndarray:
        return self.belief.sample.copy()

    @property
    def contact(self) -> bool:
        return self.belief.contact

    @property
    def revealed(self) -> bool:
        return self.belief.revealed

    @property
    def reveal_mode(self) -> Reveal:
        return self.spec.reveal

    # ------------------------------------------------------------------ simulator state
    # MuJoCo's physics (time, qpos, qvel, act), the controls and the solver's warm start: with these
    # a restored simulation renders, and steps on, exactly as the recorded one did
    MJ_STATE = mujoco.mjtState.mjSTATE_FULLPHYSICS | mujoco.mjtState.mjSTATE_CTRL | mujoco.mjtState.mjSTATE_WARMSTART

    @property
    def _fixed_bodies(self) -> list[str]:
        """Objects placed through ``model.body_pos`` at reset (outside MuJoCo's state)."""
        return [name for name, body in self.bodies.items() if self.model.body_jntnum[body] == 0]

    def sim_state(self) -> np.ndarray:
        mj = np.empty(mujoco.mj_stateSize(self.model, self.MJ_STATE))
        mujoco.mj_getState(self.model, self.data, mj, self.MJ_STATE)
        fixed = [
            np.concatenate([self.model.body_pos[self.bodies[n]], self.model.body_quat[self.bodies[n]]])
            for n in self._fixed_bodies
        ]
        return np.concatenate([mj, *fixed, self.arm.controller_state()])

    def sim_state_layout(self) -> dict:
        model = self.model
        return {
            "mujoco_state_spec": int(self.MJ_STATE),
            "mujoco_state_size": int(mujoco.mj_stateSize(model, self.MJ_STATE)),
            "fixed_bodies": [f"{name}.{k}" for name in self._fixed_bodies for k in ("pos", "quat_wxyz")],
            "controller": list(self.arm.CONTROLLER_STATE),
            "size": int(self.sim_state().shape[0]),
            "model": {"nq": int(model.nq), "nv": int(model.nv), "nu": int(model.nu), "nbody": int(model.nbody)},
        }

    def restore_sim_state(self, state: np.ndarray) -> None:
        state = np.asarray(state, dtype=float).reshape(-1)
        size = mujoco.mj_stateSize(self.model, self.MJ_STATE)
        expected = size + 7 * len(self._fixed_bodies) + len(self.arm.CONTROLLER_STATE)
        if state.shape[0] != expected:
            raise ValueError(
                f"a {self.spec.name} simulator state has {expected} values, got {state.shape[0]}: "
                "it was recorded by another task or another version of its scene"
            )
        mujoco.mj_setState(self.model, self.data, state[:size], self.MJ_STATE)
        at = size
        for name in self._fixed_bodies:
            body = self.bodies[name]
            self.model.body_pos[body] = state[at : at + 3]
            self.model.body_quat[body] = state[at + 3 : at + 7]
            at += 7
        self.arm.restore_controller_state(state[at:])
        mujoco.mj_forward(self.model, self.data)

    # ------------------------------------------------------------------ rendering
    def render(self, camera: str = "frontview", width: int = 256, height: int = 256) -> np.ndarray:
        """RGB image (H, W, 3) uint8 from one of the task's cameras (needs MUJOCO_GL=egl headless)."""
        if camera not in PANDA_CAMERAS:
            raise ValueError(f"task {self.spec.name!r} has no camera {camera!r}; its cameras: {list(PANDA_CAMERAS)}")
        if self._renderer is None or (self._renderer.width, self._renderer.height) != (width, height):
            if self._renderer is not None:
                self._renderer.close()
            try:
                self._renderer = mujoco.Renderer(self.model, height=height, width=width)
            except mujoco.FatalError as err:
                raise RuntimeError(
                    "MuJoCo could not create an OpenGL context for rendering. On a headless machine set "
                    "MUJOCO_GL=egl before starting Python (and install libegl1/libgl1-mesa-dri: scripts/setup.sh)."
                ) from err
            # the table's mirror reflection draws the scene twice: half the frame rate on a software
            # renderer for a barely visible effect (docs/benchmarks.md, camera streams)
            self._renderer.scene.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = 0
        self._renderer.update_scene(self.data, camera=PANDA_CAMERAS[camera], scene_option=self._render_option)
        return self._renderer.render()

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
