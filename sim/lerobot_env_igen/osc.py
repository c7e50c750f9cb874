"""Operational-space control of the Panda arm, computed once per physics substep.

Same law and gains as robosuite's ``OSC_POSE`` controller (kp 150, critical damping, decoupled
position/orientation, gravity and Coriolis compensation, null-space pull to the home joints).
robosuite's generic controller stack spends most of a control step in Python bookkeeping; here
the law is one compiled numba kernel fed with raw MuJoCo arrays, so a control step costs little
more than its 25 physics substeps (see ``docs/benchmarks.md``).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numba
import numpy as np


@dataclass(frozen=True)
class OscGains:
    """Controller gains (robosuite OSC_POSE defaults)."""

    kp_pos: float = 150.0
    kp_ori: float = 150.0
    damping_ratio: float = 1.0
    kp_null: float = 10.0


def orientation_error(rot_desired: np.ndarray, rot_current: np.ndarray) -> np.ndarray:
    """Small-angle rotation vector taking ``rot_current`` to ``rot_desired`` (robosuite's form).

    robosuite sums ``cross(current[:, i], desired[:, i])``; that sum is the vee of
    ``D C^T - C D^T``, which is what we compute.
    """
    a = rot_desired @ rot_current.T
    return 0.5 * np.array([a[2, 1] - a[1, 2], a[0, 2] - a[2, 0], a[1, 0] - a[0, 1]])


_RIDGE = 1e-8


@numba.njit(cache=True)
def _osc_kernel(
    jacp,
    jacr,
    mass_full,
    d0,
    n,
    qvel_all,
    qpos_arm,
    bias_all,
    pos,
    rot,
    goal_pos,
    goal_rot,
    kp,
    kd,
    home,
    kp_null,
    kd_null,
):  # pragma: no cover - compiled
    jac = np.empty((6, n))
    jac[:3] = jacp[:, d0 : d0 + n]
    jac[3:] = jacr[:, d0 : d0 + n]
    mass = np.ascontiguousarray(mass_full[d0 : d0 + n, d0 : d0 + n])
    qvel = qvel_all[d0 : d0 + n].copy()
    twist = jac @ qvel
    a = goal_rot @ rot.T
    err = np.empty(6)
    err[:3] = goal_pos - pos
    err[3] = 0.5 * (a[2, 1] - a[1, 2])
    err[4] = 0.5 * (a[0, 2] - a[2, 0])
    err[5] = 0.5 * (a[1, 0] - a[0, 1])
    desired = kp * err - kd * twist
    mass_inv = np.linalg.inv(mass)
    jm = jac @ mass_inv
    # A tiny ridge keeps the inverses finite at kinematic singularities (robosuite uses pinv).
    lam_inv = jm @ jac.T + _RIDGE * np.eye(6)
    lam_pos = np.linalg.inv(np.ascontiguousarray(lam_inv[:3, :3]))
    lam_ori = np.linalg.inv(np.ascontiguousarray(lam_inv[3:, 3:]))
    lam_full = np.linalg.inv(lam_inv)
    wrench = np.empty(6)
    wrench[:3] = lam_pos @ desired[:3]
    wrench[3:] = lam_ori @ desired[3:]
    tau = jac.T @ wrench + bias_all[d0 : d0 + n]
    jbar = mass_inv @ jac.T @ lam_full
    null = np.eye(n) - jbar @ jac
    pose_torque = mass @ (kp_null * (home - qpos_arm) - kd_null * qvel)
    return tau + null.T @ pose_torque


class OperationalSpaceController:
    """Torques that drive a site to a goal pose; the arm's dofs must be contiguous."""

    def __init__(
        self,
        model: mujoco.MjModel,
        site_id: int,
        dof_ids: np.ndarray,
        home_qpos: np.ndarray,
        qpos_ids: np.ndarray,
        gains: OscGains | None = None,
    ) -> None:
        dof_ids, qpos_ids = np.asarray(dof_ids), np.asarray(qpos_ids)
        for label, ids in (("dof", dof_ids), ("qpos", qpos_ids)):
            if not np.array_equal(ids, np.arange(ids[0], ids[0] + len(ids))):
                raise ValueError(f"arm {label} indices must be contiguous, got {ids.tolist()}")
        self._model = model
        self._site = site_id
        self._d0, self._n = int(dof_ids[0]), len(dof_ids)
        self._qpos = slice(int(qpos_ids[0]), int(qpos_ids[0]) + len(qpos_ids))
        self._home = np.asarray(home_qpos, dtype=float)
        self.set_gains(gains or OscGains())
        self._jacp = np.zeros((3, model.nv))
        self._jacr = np.zeros((3, model.nv))
        self._mass_full = np.zeros((model.nv, model.nv))
        self._bound: mujoco.MjData | None = None
        self._bound_views: tuple = ()

    def set_gains(self, gains: OscGains) -> None:
        """Track with other gains from the next torque on (critical damping follows the stiffness)."""
        self.gains = gains
        self._kp = np.array([gains.kp_pos] * 3 + [gains.kp_ori] * 3)
        self._kd = 2.0 * np.sqrt(self._kp) * gains.damping_ratio
        self._kp_null = float(gains.kp_null)
        self._kd_null = float(2.0 * np.sqrt(gains.kp_null))

    def _views(self, data: mujoco.MjData) -> tuple:
        """Views into ``data``'s buffers (they live as long as ``data``), built once per MjData.

        Each attribute access on an MjData builds a fresh numpy view; at 25 substeps per control
        step those accesses cost more than the arithmetic, so they are made once.
        """
        if self._bound is not data:
            self._bound = data
            self._bound_views = (
                data.qM,
                data.qvel,
                data.qpos[self._qpos],
                data.qfrc_bias,
                data.site_xpos[self._site],
                data.site_xmat[self._site].reshape(3, 3),
            )
        return self._bound_views

    def torques(self, data: mujoco.MjData, goal_pos: np.ndarray, goal_rot: np.ndarray) -> np.ndarray:
        """Joint torques for the arm given the current kinematics in ``data`` (after ``mj_step1``)."""
        qM, qvel, qpos, qfrc_bias, site_pos, site_rot = self._views(data)
        mujoco.mj_jacSite(self._model, data, self._jacp, self._jacr, self._site)
        mujoco.mj_fullM(self._model, self._mass_full, qM)
        return _osc_kernel(
            self._jacp,
            self._jacr,
            self._mass_full,
            self._d0,
            self._n,
            qvel,
            qpos,
            qfrc_bias,
            site_pos,
            site_rot,
            goal_pos,
            goal_rot,
            self._kp,
            self._kd,
            self._home,
            self._kp_null,
            self._kd_null,
        )
