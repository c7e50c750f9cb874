"""What the deployed robot believes about the corrupted object: the core's belief model, fed from perception.

The policy was trained on its task's observations (Block Grasp: about the cube), built by
:func:`igen_lerobot.core.observation.observation` from the end-effector pose, the gripper width,
the cube pose *as the robot believes it* and the belief's contact/revealed values. The deployment
keeps the same :class:`~igen_lerobot.core.belief.ObjectBelief` the simulator keeps: the perceived
pose plus the episode's test-time pose error until the first contact, then what the reveal mode
allows. On a real arm the contact is felt (external force), so ``contact_position`` is the
hand's position at that moment rather than the contact points.
"""

from __future__ import annotations

import numpy as np

from igen_lerobot.core.belief import ObjectBelief, Reveal
from igen_lerobot.core.error_models import BoxNoise
from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.core.task import TaskSpec

DEPLOYED_OBJECT = "cube"


def cube_belief(offset: np.ndarray, reveal: Reveal) -> ObjectBelief:
    """A fresh belief for one episode: the corrupted object is believed ``offset`` [m] away until touched."""
    # any position-offset model applies a sample the same way; its bounds play no part here
    return ObjectBelief(BoxNoise(), np.asarray(offset, dtype=float).reshape(3), Reveal(reveal))


def check_deployable(spec: TaskSpec, truth: bool = False) -> None:
    """Refuse a task the configured perception cannot see.

    The cameras (RealSense, rendered D415, franky-sim's scene channel) perceive one cube and the arm
    feels contacts with it, so they deploy Block Grasp only. ``truth`` (the simulator's poses, a
    rehearsal) knows every object of any task.
    """
    if truth:
        return
    if spec.objects != (DEPLOYED_OBJECT,) or spec.reveal_contact != ("gripper", DEPLOYED_OBJECT):
        raise ConfigError(
            f"igen-deploy's cameras perceive a single cube and reveal on gripper-cube contact; task {spec.name!r} has "
            f"objects {spec.objects} revealed on {spec.reveal_contact}: deploy a Block Grasp policy, or rehearse "
            "this task with --robot.type=sim --perception.type=truth"
        )
