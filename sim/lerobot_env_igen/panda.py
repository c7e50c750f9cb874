"""A Panda arm with its gripper inside a compiled scene: reset, control period, contacts.

Control: every control period holds one Cartesian goal (position and orientation) and runs
``substeps`` physics steps of 2 ms, computing OSC torques at each (``mj_step1`` -> torques ->
``mj_step2``, as robosuite does). The gripper is a binary command rate-limited like robosuite's
Panda gripper controller. A period can watch one pair of geom sets (say, nut and peg) and
report where they first touched.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import mujoco
import numba
import numpy as np

from lerobot_env_igen.osc import OperationalSpaceController, OscGains, orientation_error
from lerobot_env_igen.scene import SceneNames

# World orientation of the end effector the tasks hold: approach axis down, fingers along world y.
TOP_DOWN_ROT = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])
GRIPPER_RATE = 0.2  # change of the normalised finger command per control period (robosuite's)
FINGER_OPEN = 0.04  # [m] per finger
SCENE_NAMES = SceneNames()
DEFAULT_GAINS = OscGains()


@numba.njit(cache=True)
def _any_pair(pairs, mask_a, mask_b):  # pragma: no cover - compiled
    for i in range(pairs.shape[0]):
        g1, g2 = pairs[i, 0], pairs[i, 1]
        if (mask_a[g1] and mask_b[g2]) or (mask_a[g2] and mask_b[g1]):
            return True
    return False


@numba.njit(cache=True)
def _pair_mask(pairs, mask_a, mask_b):  # pragma: no cover - compiled
    out = np.zeros(pairs.shape[0], dtype=np.bool_)
    for i in range(pairs.shape[0]):
        g1, g2 = pairs[i, 0], pairs[i, 1]
        out[i] = (mask_a[g1] and mask_b[g2]) or (mask_a[g2] and mask_b[g1])
    return out


@dataclass(frozen=True)
class ContactEvent:
    """Where a watched pair of geom sets first touched during a control period."""

    position: np.ndarray  # [m] mean of the pair's contact points at that substep
    geom_pairs: np.ndarray  # (k, 2) the touching geom ids


def _ids(model: mujoco.MjModel, kind: mujoco.mjtObj, names: tuple[str, ...]) -> np.ndarray:
    return np.array([mujoco.mj_name2id(model, kind, n) for n in names])


class PandaArm:
    """Owns the MjData of a Panda scene and steps it under OSC."""

    def __init__(
        self,
        model: mujoco.MjModel,
        default_qpos: np.ndarray,
        home_pos: np.ndarray,
        control_hz: int,
        names: SceneNames = SCENE_NAMES,
        gains: OscGains = DEFAULT_GAINS,
        home_rot: np.ndarray = TOP_DOWN_ROT,
    ) -> None:
        self.model = model
        self.data = mujoco.MjData(model)
        self.names = names
        obj = mujoco.mjtObj
        arm_joints = _ids(model, obj.mjOBJ_JOINT, names.arm_joints)
        finger_joints = _ids(model, obj.mjOBJ_JOINT, names.finger_joints)
        self.arm_qpos = model.jnt_qposadr[arm_joints]
        self.arm_dofs = model.jnt_dofadr[arm_joints]
        self.finger_qpos = model.jnt_qposadr[finger_joints]
        self.arm_act = _ids(model, obj.mjOBJ_ACTUATOR, names.arm_actuators)
        self.finger_act = _ids(model, obj.mjOBJ_ACTUATOR, names.finger_actuators)
        self.site = mujoco.mj_name2id(model, obj.mjOBJ_SITE, names.eef_site)
        self.substeps = int(round(1.0 / control_hz / model.opt.timestep))
        if self.substeps < 1:
            raise ValueError(f"control_hz={control_hz} is faster than the physics step {model.opt.timestep} s")
        self.gripper_geoms = self._gripper_geom_ids()
        self.gripper_geom_mask = self.geom_mask(self.gripper_geoms)
        self.home_rot = np.asarray(home_rot, dtype=float)
        self.home_qpos = self._solve_home(default_qpos, np.asarray(home_pos, float))
        self.osc = OperationalSpaceController(model, self.site, self.arm_dofs, self.home_qpos, self.arm_qpos, gains)
        self.gains = gains
        self.latency_substeps = 0  # substeps of each period that still track the previous goal (set_dynamics)
        self.goal_pos = np.zeros(3)
        self.goal_rot = self.home_rot.copy()
        self._gripper_level = -1.0  # -1 open ... +1 closed
        self.peak_contact_force = 0.0  # [N] see control_period(measure_force=True)

    def set_dynamics(self, kp_scale: float = 1.0, latency: float = 0.0) -> None:
        """Another arm's response: stiffness times ``kp_scale``, goals applied ``latency`` [s] late.

        The latency is rounded to whole physics substeps; it must be shorter than a control period.
        """
        scaled = replace(self.gains, kp_pos=self.gains.kp_pos * kp_scale, kp_ori=self.gains.kp_ori * kp_scale)
        self.osc.set_gains(scaled)
        substeps = int(round(latency / self.model.opt.timestep))
        if not 0 <= substeps < self.substeps:
            raise ValueError(f"latency {latency} s must be shorter than the control period")
        self.latency_substeps = substeps

    # ------------------------------------------------------------------ kinematics
    def _gripper_geom_ids(self) -> np.ndarray:
        """All collision geoms of the hand and fingers (bodies under the gripper root)."""
        root = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, self.names.gripper_body_root)
        bodies = {root}
        for b in range(self.model.nbody):
            parent = self.model.body_parentid[b]
            if parent in bodies or b in bodies:
                bodies.add(b)
        # Hand links above the gripper root touch objects too (the Panda hand).
        hand = self.model.body_parentid[root]
        bodies.add(hand)
        geoms = [
            g
            for g in range(self.model.ngeom)
            if self.model.geom_bodyid[g] in bodies and self.model.geom_contype[g] | self.model.geom_conaffinity[g]
        ]
        return np.array(sorted(geoms))

    def _solve_home(self, start_qpos: np.ndarray, target_pos: np.ndarray) -> np.ndarray:
        """Joint configuration with the end effector at ``target_pos`` in ``home_rot`` (damped least squares)."""
        data = mujoco.MjData(self.model)
        data.qpos[self.arm_qpos] = start_qpos
        jacp, jacr = np.zeros((3, self.model.nv)), np.zeros((3, self.model.nv))
        for _ in range(200):
            mujoco.mj_kinematics(self.model, data)
            pos = data.site_xpos[self.site]
            rot = data.site_xmat[self.site].reshape(3, 3)
            err = np.concatenate([target_pos - pos, orientation_error(self.home_rot, rot)])
            if np.linalg.norm(err) < 1e-6:
                break
            mujoco.mj_comPos(self.model, data)
            mujoco.mj_jacSite(self.model, data, jacp, jacr, self.site)
            jac = np.concatenate([jacp[:, self.arm_dofs], jacr[:, self.arm_dofs]])
            dq = jac.T @ np.linalg.solve(jac @ jac.T + 1e-4 * np.eye(6), err)
            data.qpos[self.arm_qpos] += dq
        return data.qpos[self.arm_qpos].copy()

    # ------------------------------------------------------------------ state
    def reset(self) -> None:
        """Arm at home, fingers open, everything at rest (objects are placed by the task)."""
        mujoco.mj_resetData(self.model, self.data)
        self.data.qpos[self.arm_qpos] = self.home_qpos
        self.data.qpos[self.finger_qpos] = (FINGER_OPEN, -FINGER_OPEN)
        self._gripper_level = -1.0
        self._apply_gripper_ctrl()
        mujoco.mj_forward(self.model, self.data)
        self.goal_pos = self.data.site_xpos[self.site].copy()
        self.goal_rot = self.home_rot.copy()

    CONTROLLER_STATE = ("gripper_level", *(f"goal_pos.{a}" for a in "xyz"), *(f"goal_rot.{i}" for i in range(9)))

    def controller_state(self) -> np.ndarray:
        """What the next control period depends on besides the physics: gripper level and goal pose."""
        return np.concatenate([[self._gripper_level], self.goal_pos, self.goal_rot.reshape(-1)])

    def restore_controller_state(self, state: np.ndarray) -> None:
        self._gripper_level = float(state[0])
        self.goal_pos = np.array(state[1:4], dtype=float)
        self.goal_rot = np.ascontiguousarray(np.reshape(state[4:13], (3, 3)), dtype=float)

    def eef_pose(self) -> np.ndarray:
        pose = np.eye(4)
        pose[:3, :3] = self.data.site_xmat[self.site].reshape(3, 3)
        pose[:3, 3] = self.data.site_xpos[self.site]
        return pose

    def eef_pos(self) -> np.ndarray:
        return self.data.site_xpos[self.site].copy()

    def eef_quat_xyzw(self) -> np.ndarray:
        quat_wxyz = np.empty(4)
        mujoco.mju_mat2Quat(quat_wxyz, self.data.site_xmat[self.site])
        return np.array([quat_wxyz[1], quat_wxyz[2], quat_wxyz[3], quat_wxyz[0]])

    def gripper_width(self) -> float:
        q = self.data.qpos[self.finger_qpos]
        return float(q[0] - q[1])

    @property
    def gripper_commanded_closed(self) -> bool:
        """Whether the fingers are being closed (an in-hand task starts with them closed on its part)."""
        return self._gripper_level > 0.0

    # ------------------------------------------------------------------ control
    def hold_closed(self, finger_opening: float) -> None:
        """Put the fingers at ``finger_opening`` [m] each, commanded closed (an object starts in the hand)."""
        self.data.qpos[self.finger_qpos] = (finger_opening, -finger_opening)
        self._gripper_level = 1.0
        self._apply_gripper_ctrl()

    def _apply_gripper_ctrl(self) -> None:
        opening = FINGER_OPEN * 0.5 * (1.0 - self._gripper_level)  # level -1 -> open, +1 -> closed
        self.data.ctrl[self.finger_act] = (opening, -opening)

    def geom_mask(self, geoms: np.ndarray) -> np.ndarray:
        """Boolean lookup over all geoms, for cheap contact tests inside the substep loop."""
        mask = np.zeros(self.model.ngeom, dtype=bool)
        mask[np.asarray(geoms, dtype=int)] = True
        return mask

    def control_period(
        self,
        goal_pos: np.ndarray,
        close_gripper: bool,
        goal_rot: np.ndarray | None = None,
        watch: tuple[np.ndarray, np.ndarray] | None = None,
        measure_force: bool = False,
    ) -> ContactEvent | None:
        """Hold ``goal_pos`` and ``goal_rot`` (default: the last goal orientation) for one control period.

        ``watch`` is a pair of geom masks (see :meth:`geom_mask`); the return value says where
        they first touched during the period, or None if they did not. With ``measure_force``,
        :attr:`peak_contact_force` is the largest :meth:`contact_force` seen during the period
        (what a real arm's external-force estimate would show).
        """
        late_pos, late_rot = self.goal_pos, self.goal_rot  # what a late goal leaves the arm tracking
        self.goal_pos = np.asarray(goal_pos, dtype=float)
        if goal_rot is not None:
            self.goal_rot = np.ascontiguousarray(goal_rot, dtype=float)
        step = GRIPPER_RATE if close_gripper else -GRIPPER_RATE
        self._gripper_level = min(1.0, max(-1.0, self._gripper_level + step))
        self._apply_gripper_ctrl()
        # the substep loop runs 25 times per period: everything it touches is bound locally
        model, data, act = self.model, self.data, self.arm_act
        torques, goal_pos, goal_rot = self.osc.torques, self.goal_pos, self.goal_rot
        step1, step2 = mujoco.mj_step1, mujoco.mj_step2
        mask_a, mask_b = watch if watch is not None else (None, None)
        event: ContactEvent | None = None
        watching = watch is not None
        self.peak_contact_force = 0.0
        late = self.latency_substeps
        for substep in range(self.substeps):
            step1(model, data)
            if substep < late:
                data.ctrl[act] = torques(data, late_pos, late_rot)
            else:
                data.ctrl[act] = torques(data, goal_pos, goal_rot)
            step2(model, data)
            if watching and data.ncon and _any_pair(data.contact.geom[: data.ncon], mask_a, mask_b):
                event = self._first_contact(mask_a, mask_b)
                watching = False
            if measure_force:
                self.peak_contact_force = max(self.peak_contact_force, self.contact_force())
        return event

    def in_contact(self, mask_a: np.ndarray, mask_b: np.ndarray) -> bool:
        """Whether any geom in ``mask_a`` touches any geom in ``mask_b`` now."""
        ncon = self.data.ncon
        return bool(ncon) and bool(_any_pair(self.data.contact.geom[:ncon], mask_a, mask_b))

    def _first_contact(self, mask_a: np.ndarray, mask_b: np.ndarray) -> ContactEvent | None:
        ncon = self.data.ncon
        pairs = self.data.contact.geom[:ncon]
        if not _any_pair(pairs, mask_a, mask_b):
            return None
        hits = _pair_mask(pairs, mask_a, mask_b)
        return ContactEvent(position=self.data.contact.pos[:ncon][hits].mean(axis=0), geom_pairs=pairs[hits].copy())

    def contact_force(self) -> float:
        """Magnitude of the net contact force on the hand and fingers from everything else [N]."""
        ncon = self.data.ncon
        if ncon == 0:
            return 0.0
        total = np.zeros(3)
        wrench = np.zeros(6)
        mask = self.gripper_geom_mask
        for i in range(ncon):
            contact = self.data.contact[i]
            g1, g2 = contact.geom1, contact.geom2
            if mask[g1] == mask[g2]:
                continue  # not a gripper contact, or the fingers touching each other
            mujoco.mj_contactForce(self.model, self.data, i, wrench)
            force = contact.frame.reshape(3, 3).T @ wrench[:3]  # contact frame -> world, acting on geom2
            total += force if mask[g2] else -force
        return float(np.linalg.norm(total))
