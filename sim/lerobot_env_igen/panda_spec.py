"""What every Panda table-top task's static description shares. Importable without MuJoCo.

One table height for the scene, the task specs and the scripted rules; the Panda tasks' control
rate, episode length, cameras and action names; and :func:`panda_spec`, which fills those in so a
task's ``spec.py`` writes only what is its own.
"""

from __future__ import annotations

from igen_lerobot.core.error_models import POSITION_ERROR_NAMES
from igen_lerobot.core.task import SubtaskSpec, TaskSpec
from lerobot_env_igen.cameras import PANDA_CAMERAS

TABLE_TOP_Z = 0.8  # [m] world height of the table surface
PANDA_FPS = 20  # [Hz] the paper's control rate
PANDA_EPISODE_STEPS = 200  # control steps in an episode, unless a task needs more
GRIPPER = "gripper"  # the hand and fingers, as a contact party (``TaskSpec.reveal_contact``)
PAD_ABOVE_GRIP = 0.0036  # [m] the finger pads' centres sit this far above the grip site (top-down hand)

POSITION_ACTION_NAMES = ("delta.x", "delta.y", "delta.z", "gripper")  # DeltaPositionActions
POSE_ACTION_NAMES = ("delta.x", "delta.y", "delta.z", "delta.rx", "delta.ry", "delta.rz", "gripper")  # DeltaPoseActions


def panda_spec(
    *,
    name: str,
    instruction: str,
    objects: tuple[str, ...],
    subtasks: tuple[SubtaskSpec, ...],
    action_names: tuple[str, ...],
    corrupted_object: str,
    reveal_contact: tuple[str, str] | None,
    error_names: tuple[str, ...] = POSITION_ERROR_NAMES,
    max_episode_steps: int = PANDA_EPISODE_STEPS,
    **fields,
) -> TaskSpec:
    """A Panda task's :class:`~igen_lerobot.core.task.TaskSpec`: robot, rate, cameras filled in.

    ``error_names`` are the error model's value names (``dx, dy, dz`` for a position error); they
    are stored as ``<corrupted_object>.<name>``. Any other ``TaskSpec`` field (``boxes``) passes through.
    """
    return TaskSpec(
        name=name,
        instruction=instruction,
        robot_type="panda",
        fps=PANDA_FPS,
        max_episode_steps=max_episode_steps,
        objects=objects,
        subtasks=subtasks,
        action_names=action_names,
        corrupted_object=corrupted_object,
        corruption_names=tuple(f"{corrupted_object}.{n}" for n in error_names),
        reveal_contact=reveal_contact,
        cameras=tuple(PANDA_CAMERAS),
        **fields,
    )
