"""Poses in one convention, so sim, generation, ICP and the Franka agree.

Convention (used everywhere in igen-lerobot):

* A pose is a 4x4 homogeneous transform ``T_parent_child`` (float64) mapping points in the child
  frame to the parent frame: ``p_parent = T_parent_child @ p_child``. Names carry both frames,
  e.g. ``T_world_eef``, ``T_world_obj``.
* Quaternions are **scalar-last** ``(x, y, z, w)``, as in scipy and robosuite. MuJoCo's native
  scalar-first ``(w, x, y, z)`` is converted only at the simulator boundary
  (:func:`quat_wxyz_to_xyzw`).
* Positions are in metres.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

try:  # scipy's compiled conversions, the ones ``Rotation`` calls for numpy input (see _compiled)
    from scipy.spatial.transform import _rotation_cy as _compiled_rotations
except ImportError:  # pragma: no cover - a scipy without them: the public API, slower, same numbers
    _compiled_rotations = None

__all__ = [
    "make_pose",
    "pose_inv",
    "pose_to_pos_quat",
    "pos_quat_to_pose",
    "quat_wxyz_to_xyzw",
    "quat_xyzw_to_wxyz",
    "rotation_angle",
    "transform_segment",
    "heading",
    "interpolate_poses",
    "quat_xyzw_from_matrix",
    "rotvec_from_matrix",
    "matrix_from_rotvec",
    "rot_z",
    "wrap_angle",
    "pose_vector",
]


def make_pose(pos: np.ndarray, rot: np.ndarray | None = None) -> np.ndarray:
    """4x4 pose from a position [m] and a 3x3 rotation (identity if omitted)."""
    pose = np.eye(4)
    pose[:3, 3] = np.asarray(pos, dtype=float)
    if rot is not None:
        pose[:3, :3] = np.asarray(rot, dtype=float)
    return pose


def pose_inv(pose: np.ndarray) -> np.ndarray:
    """Inverse of a rigid transform (or a stack of them), without a general matrix inverse."""
    pose = np.asarray(pose, dtype=float)
    inv = np.zeros_like(pose)
    rot_t = np.swapaxes(pose[..., :3, :3], -1, -2)
    inv[..., :3, :3] = rot_t
    inv[..., :3, 3] = -np.einsum("...ij,...j->...i", rot_t, pose[..., :3, 3])
    inv[..., 3, 3] = 1.0
    return inv


def pose_to_pos_quat(pose: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Split a pose (or stack) into position [m] and quaternion (x, y, z, w)."""
    pose = np.asarray(pose, dtype=float)
    rot = pose[..., :3, :3]
    if _compiled_rotations is None or rot.ndim > 3:
        return pose[..., :3, 3].copy(), Rotation.from_matrix(rot).as_quat()
    quat = _quats_from_matrices(rot)
    quat = _compiled_rotations.as_quat(np.atleast_2d(quat), canonical=False, scalar_first=False)
    return pose[..., :3, 3].copy(), quat[0] if rot.ndim == 2 else quat


def _quats_from_matrices(rot: np.ndarray) -> np.ndarray:
    """The quaternions of scipy's ``from_matrix``, skipping its validation where it cannot change a bit of the result.

    Unless told the input is valid, scipy checks every matrix (determinant, Gram matrix against
    the identity with ``atol=1e-12``) and projects the ones off by more onto the nearest rotation;
    those checks cost several times the conversion (benchmarks/rotation_check_cost.py). A single
    matrix that is orthonormal to rounding (Gram matrix off the identity by <= 1e-13, ten times
    inside scipy's tolerance, so the two sums' rounding cannot disagree) and right-handed is
    converted as valid: scipy would not have touched it. Anything else, stacks included, takes
    scipy's full path.
    """
    if rot.ndim == 2 and _orthonormal_to_rounding(rot):
        return _compiled_rotations.from_matrix(rot, assume_valid=True)
    return _compiled_rotations.from_matrix(rot, assume_valid=False)


def _orthonormal_to_rounding(rot: np.ndarray) -> bool:
    m0, m1, m2, m3, m4, m5, m6, m7, m8 = rot.reshape(9).tolist()
    gram_diagonal = (m0 * m0 + m1 * m1 + m2 * m2, m3 * m3 + m4 * m4 + m5 * m5, m6 * m6 + m7 * m7 + m8 * m8)
    gram_off_diagonal = (m0 * m3 + m1 * m4 + m2 * m5, m0 * m6 + m1 * m7 + m2 * m8, m3 * m6 + m4 * m7 + m5 * m8)
    det = m0 * (m4 * m8 - m5 * m7) - m1 * (m3 * m8 - m5 * m6) + m2 * (m3 * m7 - m4 * m6)
    return (
        det > 0
        and all(abs(g - 1.0) <= 1e-6 for g in gram_diagonal)  # scipy's rtol gives the diagonal 1e-5
        and all(abs(g) <= 1e-13 for g in gram_off_diagonal)
    )


def pos_quat_to_pose(pos: np.ndarray, quat_xyzw: np.ndarray) -> np.ndarray:
    """Pose (or stack) from position [m] and quaternion (x, y, z, w); the quaternion is normalised."""
    pos = np.asarray(pos, dtype=float)
    quat = np.asarray(quat_xyzw, dtype=float)
    if _compiled_rotations is None or quat.ndim > 2:
        rot = Rotation.from_quat(quat).as_matrix()
    else:
        normalised = _compiled_rotations.from_quat(np.atleast_2d(quat), normalize=True, copy=True, scalar_first=False)
        rot = _compiled_rotations.as_matrix(normalised)
        rot = rot[0] if quat.ndim == 1 else rot
    pose = np.zeros(pos.shape[:-1] + (4, 4))
    pose[..., :3, :3] = rot
    pose[..., :3, 3] = pos
    pose[..., 3, 3] = 1.0
    return pose


def quat_wxyz_to_xyzw(quat_wxyz: np.ndarray) -> np.ndarray:
    """MuJoCo (scalar-first) to our scalar-last order."""
    return np.roll(np.asarray(quat_wxyz, dtype=float), -1, axis=-1)


def quat_xyzw_to_wxyz(quat_xyzw: np.ndarray) -> np.ndarray:
    """Our scalar-last order to MuJoCo (scalar-first)."""
    return np.roll(np.asarray(quat_xyzw, dtype=float), 1, axis=-1)


def rotation_angle(rot_a: np.ndarray, rot_b: np.ndarray) -> float:
    """Geodesic angle [rad] between two rotation matrices."""
    rel = np.asarray(rot_a).T @ np.asarray(rot_b)
    cos = np.clip((np.trace(rel) - 1.0) / 2.0, -1.0, 1.0)
    return float(np.arccos(cos))


def transform_segment(
    T_world_eef_src: np.ndarray, T_world_obj_src: np.ndarray, T_world_obj_new: np.ndarray
) -> np.ndarray:
    """Move a source end-effector path into a new object frame (MimicGen's transform).

    Keeps every pose's relation to the object fixed:
    ``T_new_eef = T_new_obj · inv(T_src_obj) · T_src_eef``.

    Args:
        T_world_eef_src: (N, 4, 4) source end-effector poses.
        T_world_obj_src: (4, 4) pose of the object the segment is relative to, in the source.
        T_world_obj_new: (4, 4) pose of the same object in the new scene.
    """
    T_new_src = np.asarray(T_world_obj_new, dtype=float) @ pose_inv(T_world_obj_src)
    return np.einsum("ij,njk->nik", T_new_src, np.asarray(T_world_eef_src, dtype=float))


def interpolate_poses(T_start: np.ndarray, T_end: np.ndarray, num_steps: int) -> np.ndarray:
    """``num_steps`` poses strictly after ``T_start`` up to and including ``T_end``.

    Positions are interpolated linearly and rotations by slerp, the way MimicGen bridges the
    robot's current pose and the start of a transformed segment.
    """
    if num_steps < 1:
        raise ValueError(f"num_steps must be >= 1 to reach the target pose, got {num_steps}")
    fractions = np.arange(1, num_steps + 1) / num_steps
    pos = (1.0 - fractions)[:, None] * T_start[:3, 3] + fractions[:, None] * T_end[:3, 3]
    slerp = Slerp([0.0, 1.0], Rotation.from_matrix(np.stack([T_start[:3, :3], T_end[:3, :3]])))
    out = np.tile(np.eye(4), (num_steps, 1, 1))
    out[:, :3, :3] = slerp(fractions).as_matrix()
    out[:, :3, 3] = pos
    return out


def quat_xyzw_from_matrix(rot: np.ndarray) -> np.ndarray:
    """Quaternion (x, y, z, w) of a rotation matrix, with MuJoCo's choice between ``q`` and ``-q``.

    ``q`` and ``-q`` are the same rotation; which one a policy sees is a convention it learns.
    Observations are built with MuJoCo's (``mju_mat2Quat``: the largest component is positive),
    here without MuJoCo so the core, the simulator and the real robot all give the same numbers.
    It runs on every observation, hence plain floats rather than numpy scalars.
    """
    m0, m1, m2, m3, m4, m5, m6, m7, m8 = np.asarray(rot, dtype=float).reshape(9).tolist()
    trace = m0 + m4 + m8
    if trace > 0:
        w = 0.5 * math.sqrt(1.0 + trace)
        q = (w, 0.25 * (m7 - m5) / w, 0.25 * (m2 - m6) / w, 0.25 * (m3 - m1) / w)
    elif m0 > m4 and m0 > m8:
        x = 0.5 * math.sqrt(1.0 + m0 - m4 - m8)
        q = (0.25 * (m7 - m5) / x, x, 0.25 * (m1 + m3) / x, 0.25 * (m2 + m6) / x)
    elif m4 > m8:
        y = 0.5 * math.sqrt(1.0 - m0 + m4 - m8)
        q = (0.25 * (m2 - m6) / y, 0.25 * (m1 + m3) / y, y, 0.25 * (m5 + m7) / y)
    else:
        z = 0.5 * math.sqrt(1.0 - m0 - m4 + m8)
        q = (0.25 * (m3 - m1) / z, 0.25 * (m2 + m6) / z, 0.25 * (m5 + m7) / z, z)
    norm = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    return np.array((q[1] / norm, q[2] / norm, q[3] / norm, q[0] / norm))


def pose_vector(pose: np.ndarray) -> np.ndarray:
    """Position [m] + quaternion xyzw (MuJoCo's sign) of a 4x4 pose: the 7 numbers observations hold."""
    out = np.empty(7)
    out[:3] = pose[:3, 3]
    out[3:] = quat_xyzw_from_matrix(pose[:3, :3])
    return out


def rotvec_from_matrix(rot: np.ndarray) -> np.ndarray:
    """Axis-angle vector [rad] (axis times angle) of a rotation matrix."""
    rot = np.asarray(rot, dtype=float)
    if _compiled_rotations is None or rot.ndim != 2:
        return Rotation.from_matrix(rot).as_rotvec()
    quat = _quats_from_matrices(rot)
    return _compiled_rotations.as_rotvec(quat[None], degrees=False)[0]


def matrix_from_rotvec(rotvec: np.ndarray) -> np.ndarray:
    """Rotation matrix of an axis-angle vector [rad]."""
    rotvec = np.asarray(rotvec, dtype=float)
    if _compiled_rotations is None or rotvec.ndim != 1:
        return Rotation.from_rotvec(rotvec).as_matrix()
    quat = _compiled_rotations.from_rotvec(rotvec, degrees=False)
    return _compiled_rotations.as_matrix(quat[None])[0]


def wrap_angle(angle: np.ndarray | float) -> np.ndarray | float:
    """Angles [rad] wrapped into [-pi, pi)."""
    return (np.asarray(angle) + np.pi) % (2 * np.pi) - np.pi


def heading(rot: np.ndarray) -> np.ndarray | float:
    """The heading [rad] of rotations' x axes in the xy plane (``rot`` (3, 3) or (..., 3, 3))."""
    return np.arctan2(rot[..., 1, 0], rot[..., 0, 0])


def rot_z(angle: float) -> np.ndarray:
    """Rotation by ``angle`` [rad] about the z axis."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
