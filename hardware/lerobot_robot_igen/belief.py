"""What the deployed robot believes about the cube, and the observation built from it.

The policy was trained on Block Grasp observations (``lerobot_env_igen.block_grasp.env``):
the end-effector pose and gripper width, then the cube pose *as the robot believes it*, the
contact signal and the latched ``revealed`` flag. :class:`CubeBelief` reproduces that belief
from perception: the perceived pose plus the episode's test-time pose error until the first
contact, the perceived pose after it (``Reveal.FULL``), or the end-effector position at first
contact (``Reveal.CONTACT_POSITION``: a real arm knows where it touched, not the contact points).
"""

from __future__ import annotations

import numpy as np

from igen_lerobot.core.error_models import Reveal
from igen_lerobot.core.task import OBS_ENV_STATE, OBS_STATE, TaskSpec

BLOCK_GRASP_STATE = ("eef.x", "eef.y", "eef.z", "eef.qx", "eef.qy", "eef.qz", "eef.qw", "gripper.width")
BLOCK_GRASP_ENV_STATE = (
    "cube.x", "cube.y", "cube.z", "cube.qx", "cube.qy", "cube.qz", "cube.qw", "contact", "revealed"
)  # fmt: skip


class CubeBelief:
    """The cube pose the robot believes in during one episode (task frame)."""

    def __init__(self, offset: np.ndarray, reveal: Reveal) -> None:
        self.offset = np.asarray(offset, dtype=float).reshape(3)
        self.reveal = Reveal(reveal)
        self.revealed = False
        self.contact = False
        self._contact_position: np.ndarray | None = None

    def update(self, contact: bool, T_world_eef: np.ndarray) -> None:
        """Take this period's contact signal; the first contact latches ``revealed``."""
        self.contact = bool(contact)
        if self.contact and not self.revealed:
            self.revealed = True
            self._contact_position = np.array(T_world_eef[:3, 3], dtype=float)

    def believed_position(self, perceived_position: np.ndarray) -> np.ndarray:
        perceived_position = np.asarray(perceived_position, dtype=float)
        if not self.revealed or self.reveal is Reveal.NONE:
            return perceived_position + self.offset
        if self.reveal is Reveal.FULL or self._contact_position is None:
            return perceived_position.copy()
        return self._contact_position.copy()


def check_block_grasp_spec(spec: TaskSpec) -> None:
    """The observation builder below is Block Grasp's; refuse a checkpoint of another layout."""
    if tuple(spec.state_names) != BLOCK_GRASP_STATE or tuple(spec.env_state_names) != BLOCK_GRASP_ENV_STATE:
        raise ValueError(
            f"the deployment builds Block Grasp observations {BLOCK_GRASP_STATE} + {BLOCK_GRASP_ENV_STATE}; "
            f"task {spec.name!r} has {spec.state_names} + {spec.env_state_names}"
        )


def block_grasp_observation(
    T_world_eef: np.ndarray, gripper_width: float, T_world_cube: np.ndarray, belief: CubeBelief
) -> dict[str, np.ndarray]:
    """The observation exactly as ``BlockGraspEnv.observe`` lays it out (float32, quaternions xyzw)."""
    state = np.empty(8, dtype=np.float32)
    state[:3] = T_world_eef[:3, 3]
    state[3:7] = mujoco_quat_xyzw(T_world_eef[:3, :3])
    state[7] = gripper_width
    env_state = np.empty(9, dtype=np.float32)
    env_state[:3] = belief.believed_position(T_world_cube[:3, 3])
    env_state[3:7] = mujoco_quat_xyzw(T_world_cube[:3, :3])
    env_state[7] = float(belief.contact)
    env_state[8] = float(belief.revealed)
    return {OBS_STATE: state, OBS_ENV_STATE: env_state}


def mujoco_quat_xyzw(rotation: np.ndarray) -> np.ndarray:
    """Quaternion (xyzw) of a rotation matrix, with MuJoCo's choice between q and -q.

    The top-down gripper is a half turn (w = 0), where the sign is a convention: the policy was
    trained on MuJoCo's (``mju_mat2Quat``), so the deployment uses the same function.
    """
    import mujoco

    quat_wxyz = np.empty(4)
    mujoco.mju_mat2Quat(quat_wxyz, np.ascontiguousarray(rotation, dtype=float).reshape(9))
    return np.array([quat_wxyz[1], quat_wxyz[2], quat_wxyz[3], quat_wxyz[0]])
