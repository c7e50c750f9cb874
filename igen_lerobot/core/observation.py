"""The observation vectors every task and ``igen-deploy`` build, from poses and the belief.

One function per vector, so a deployed policy sees exactly the layout (and quaternion sign
convention) it was trained on: see :mod:`igen_lerobot.core.task` for the layout.
"""

from __future__ import annotations

import numpy as np

from igen_lerobot.core.belief import ObjectBelief
from igen_lerobot.core.geometry import pose_vector
from igen_lerobot.core.task import OBS_ENV_STATE, OBS_STATE, TaskSpec

__all__ = ["robot_state", "environment_state", "observation"]


def robot_state(T_world_eef: np.ndarray, gripper_width: float) -> np.ndarray:
    """``observation.state``: end-effector position + quaternion xyzw, gripper width (float32)."""
    return np.concatenate([pose_vector(T_world_eef), [gripper_width]]).astype(np.float32)


def environment_state(spec: TaskSpec, believed_poses: dict[str, np.ndarray], belief: ObjectBelief | None) -> np.ndarray:
    """``observation.environment_state``: believed object poses, then contact/revealed and the reveal hint."""
    parts = [pose_vector(believed_poses[obj]) for obj in spec.objects]
    if spec.reveal_contact is not None:
        if belief is None:
            raise ValueError(f"task {spec.name!r} observes contact/revealed, so it needs a belief")
        parts.append([float(belief.contact), float(belief.revealed)])
        parts.append(belief.hint())
    values = np.concatenate(parts).astype(np.float32)
    if values.shape != (len(spec.env_state_names),):
        raise ValueError(f"task {spec.name!r}: built {values.shape[0]} values for {len(spec.env_state_names)} names")
    return values


def observation(
    spec: TaskSpec,
    T_world_eef: np.ndarray,
    gripper_width: float,
    believed_poses: dict[str, np.ndarray],
    belief: ObjectBelief | None,
) -> dict[str, np.ndarray]:
    """Both vectors, keyed as LeRobot datasets key them."""
    return {
        OBS_STATE: robot_state(T_world_eef, gripper_width),
        OBS_ENV_STATE: environment_state(spec, believed_poses, belief),
    }
