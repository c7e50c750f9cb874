"""Nut-and-Peg Assembly's static description: importable without MuJoCo or robosuite.

Two object-centric subtasks: grasp the nut by its handle (relative to the nut), place it on the
fixed peg (relative to the peg). The error is one of geometry: the robot observes the nut's pose,
but with probability p its handle is on the other side (the core's ``flip`` error model: true yaw
= observed + pi); nothing reveals it (no reveal contact), the fingers closing on air are the cue.
"""

from igen_lerobot.core.belief import Reveal
from igen_lerobot.core.error_models import YawFlip
from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.core.task import ObjectBox, SubtaskSpec
from lerobot_env_igen.panda_spec import POSE_ACTION_NAMES, panda_spec
from lerobot_env_igen.square_nut import NUT_HALF_THICKNESS, PEG_HALF

# the paper's (robosuite NutAssembly's) nut region: x [-0.115, -0.11], y [0.11, 0.225] in the table
# frame (our world frame: the table's centre, its top at z = 0.8); yaw uniform in [0, 2 pi)
NUT_REGION_CENTER = (-0.1125, 0.1675)  # [m]
NUT_REGION_EXTENTS = (0.005, 0.115)  # [m] 0.5 x 11.5 cm
PEG_XY = (0.23, 0.10)  # [m] robosuite's peg1, fixed
# the grasp: fingers across the handle at GRIP_X out along the nut's x axis (the handle spans 2.875 to
# 7.925 cm, the ring's outer edge is at 4.375 cm); the closed opening tells what is between them
GRIP_X = 0.062  # [m]
# the pads' centres this far above the nut's mid-plane: the fingers' lower ends clear the table (at
# mid-height they rub on it and, closing on air, stall at 14-19 mm instead of closing fully)
PADS_ABOVE_NUT_CENTRE = 0.006  # [m]
HELD_WIDTH = (0.026, 0.036)  # [m] closed on the 3.175 cm handle: the opening lies in this range
EMPTY_WIDTH = 0.01  # [m] closed on air: below this opening nothing is between the fingers
EPISODE_STEPS = 400  # robomimic's Square horizon
# --env.geometry: 1 = the handle where observed, 2 = on the other side, mixture = either, p = 0.5
GEOMETRIES = {"1": 0.0, "2": 1.0, "mixture": 0.5}

SPEC = panda_spec(
    name="nut_and_peg",
    instruction="Pick up the square nut by its handle and place it onto the square peg.",
    objects=("nut", "peg"),
    subtasks=(SubtaskSpec(name="grasp", object_name="nut"), SubtaskSpec(name="place", object_name="peg")),
    action_names=POSE_ACTION_NAMES,
    corrupted_object="nut",
    reveal_contact=None,
    reveal=Reveal.NONE,
    error_names=("flip",),
    max_episode_steps=EPISODE_STEPS,
    boxes=(
        ObjectBox("nut", half_size=(0.0615, 0.04375, NUT_HALF_THICKNESS), center=(0.0178, 0.0, 0.0)),
        ObjectBox("peg", half_size=PEG_HALF),
    ),
)


def paper_corruption(geometry: str = "mixture") -> YawFlip:
    """The paper's geometry error: the handle on the other side with the probability of ``geometry``."""
    if geometry not in GEOMETRIES:
        raise ConfigError(f"env.geometry={geometry!r} is not one of {list(GEOMETRIES)}")
    return YawFlip(probability=GEOMETRIES[geometry])
