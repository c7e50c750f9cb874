"""Block Grasp's static description: importable without MuJoCo or robosuite."""

from igen_lerobot.core.error_models import BoxNoise
from igen_lerobot.core.task import SubtaskSpec, TaskSpec
from lerobot_env_igen.cameras import PANDA_CAMERAS

CUBE_HALF = 0.025  # [m] half side of the 5 cm cube
LIFT_SUCCESS = 0.04  # [m] the cube must rise this much above its resting height

SPEC = TaskSpec(
    name="block_grasp",
    instruction="Grasp the red cube and lift it.",
    robot_type="panda",
    fps=20,
    max_episode_steps=200,
    objects=("cube",),
    subtasks=(SubtaskSpec(name="grasp", object_name="cube"),),
    state_names=("eef.x", "eef.y", "eef.z", "eef.qx", "eef.qy", "eef.qz", "eef.qw", "gripper.width"),
    env_state_names=("cube.x", "cube.y", "cube.z", "cube.qx", "cube.qy", "cube.qz", "cube.qw", "contact", "revealed"),
    action_names=("delta.x", "delta.y", "delta.z", "gripper"),
    corrupted_object="cube",
    corruption_names=("cube.dx", "cube.dy", "cube.dz"),
    reveal_contact=("gripper", "cube"),
    cameras=tuple(PANDA_CAMERAS),
)


def paper_corruption() -> BoxNoise:
    """The paper's Block Grasp pose error: +-1 cm in x, +-7 cm in y with |y| >= 2.5 cm, none in z."""
    return BoxNoise(half_extent=(0.01, 0.07, 0.0), min_abs=(0.0, 0.025, 0.0), require="all")
