"""Block Grasp's static description: importable without MuJoCo or robosuite."""

from igen_lerobot.core.error_models import BoxNoise
from igen_lerobot.core.task import SubtaskSpec
from lerobot_env_igen.panda_spec import GRIPPER, POSITION_ACTION_NAMES, panda_spec

CUBE_HALF = 0.025  # [m] half side of the 5 cm cube
LIFT_SUCCESS = 0.04  # [m] the cube must rise this much above its resting height

SPEC = panda_spec(
    name="block_grasp",
    instruction="Grasp the red cube and lift it.",
    objects=("cube",),
    subtasks=(SubtaskSpec(name="grasp", object_name="cube"),),
    action_names=POSITION_ACTION_NAMES,
    corrupted_object="cube",
    reveal_contact=(GRIPPER, "cube"),
)


def paper_corruption() -> BoxNoise:
    """The paper's Block Grasp pose error: +-1 cm in x, +-7 cm in y with |y| >= 2.5 cm, none in z."""
    return BoxNoise(half_extent=(0.01, 0.07, 0.0), min_abs=(0.0, 0.025, 0.0), require="all")
