"""Nut Insertion's static description: importable without MuJoCo or robosuite."""

from igen_lerobot.core.belief import Reveal
from igen_lerobot.core.error_models import BoxNoise
from igen_lerobot.core.task import ObjectBox, SubtaskSpec, TaskSpec
from lerobot_env_igen.cameras import PANDA_CAMERAS

# robosuite's square nut (models/assets/objects/square-nut.xml): a square ring 8.75 cm outside with
# a 4.55 cm hole, 2 cm thick, and a handle box centred 5.4 cm out along the nut's x axis.
NUT_HALF_THICKNESS = 0.01  # [m]
NUT_HANDLE_GRIP_X = 0.062  # [m] where the fingers hold the handle, along the nut's x axis
PEG_HALF = (0.016, 0.016, 0.065)  # [m] a 3.2 x 3.2 cm peg standing 13 cm tall (robosuite's peg1 width)
TABLE_TOP_Z = 0.8  # [m]
PEG_CENTER_Z = TABLE_TOP_Z + PEG_HALF[2]
PEG_TOP_Z = TABLE_TOP_Z + 2 * PEG_HALF[2]
ON_PEG_XY = 0.03  # [m] robosuite's on_peg: nut centre within 3 cm of the peg axis in x and y ...
ON_PEG_Z = 0.05  # [m] ... and below the table top + 5 cm

SPEC = TaskSpec(
    name="nut_insertion",
    instruction="Place the square nut held in the hand onto the square peg.",
    robot_type="panda",
    fps=20,
    max_episode_steps=200,
    objects=("nut", "peg"),
    subtasks=(SubtaskSpec(name="insert", object_name="peg"),),
    action_names=("delta.x", "delta.y", "delta.z", "delta.rx", "delta.ry", "delta.rz", "gripper"),
    corrupted_object="peg",
    corruption_names=("peg.dx", "peg.dy", "peg.dz"),
    reveal_contact=("nut", "peg"),
    reveal=Reveal.FULL,
    boxes=(
        ObjectBox("nut", half_size=(0.0615, 0.04375, NUT_HALF_THICKNESS), center=(0.0178, 0.0, 0.0)),
        ObjectBox("peg", half_size=PEG_HALF),
    ),
    cameras=tuple(PANDA_CAMERAS),
)


def paper_corruption() -> BoxNoise:
    """The paper's Nut Insertion error on the peg position: +-4 cm per axis, at least 2 cm in one."""
    return BoxNoise(half_extent=(0.04, 0.04, 0.04), min_abs=(0.02, 0.02, 0.02), require="any")
