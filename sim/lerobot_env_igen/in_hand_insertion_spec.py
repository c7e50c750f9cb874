"""The in-hand insertion family's static description. Importable without MuJoCo.

An in-hand insertion task starts with a part in the hand (Nut Insertion's nut; 2-Piece Assembly's
piece; Coffee's pod) and ends with it released in or on a fixed target (the peg, the receptacle,
the pod holder) whose observed position is wrong until the part touches it. One subtask, relative
to the target; 6-DOF actions; the held part and the target are the only objects.
"""

from __future__ import annotations

from dataclasses import dataclass

from igen_lerobot.core.error_models import POSITION_ERROR_NAMES
from igen_lerobot.core.task import SubtaskSpec, TaskSpec
from lerobot_env_igen.panda_spec import POSE_ACTION_NAMES, panda_spec


@dataclass(frozen=True)
class InsertionGeometry:
    """The few lengths the shared env, scripted rule and takeover need [m].

    Heights are world z. The target's origin is its body frame (its centre for a robosuite box).
    """

    held: str  # the part in the hand (an object name)
    target: str  # the fixed part it goes into or onto
    held_bottom: float  # the held part's bottom below its origin
    target_top: float  # the target's top (what the held part must clear) above its origin
    target_origin_z: float  # where the target's origin stands
    seat_z: float  # where the held part's bottom is once it is in (the table for a peg)
    holding_width: float  # the fingers hold the part below this opening
    slides_in_xy: float  # off the target's axis by more than this, the part does not go in: a mistake


def in_hand_insertion_spec(
    *,
    name: str,
    instruction: str,
    geometry: InsertionGeometry,
    error_names: tuple[str, ...] = POSITION_ERROR_NAMES,
    **fields,
) -> TaskSpec:
    """The spec of an in-hand insertion task: objects (held, target), one ``insert`` subtask, 6-DOF actions.

    The target's observed pose carries the error (``<target>.dx`` ...), revealed by the held part
    touching it. Other ``TaskSpec`` fields (``boxes``, ``max_episode_steps``) pass through.
    """
    held, target = geometry.held, geometry.target
    return panda_spec(
        name=name,
        instruction=instruction,
        objects=(held, target),
        subtasks=(SubtaskSpec(name="insert", object_name=target),),
        action_names=POSE_ACTION_NAMES,
        corrupted_object=target,
        reveal_contact=(held, target),
        error_names=error_names,
        **fields,
    )
