"""Nut Insertion's static description: importable without MuJoCo or robosuite."""

from igen_lerobot.core.error_models import BoxNoise
from igen_lerobot.core.task import ObjectBox
from lerobot_env_igen.in_hand_insertion_spec import InsertionGeometry, in_hand_insertion_spec
from lerobot_env_igen.panda_spec import TABLE_TOP_Z
from lerobot_env_igen.square_nut import NUT_HALF_THICKNESS, PEG_CENTER_Z, PEG_HALF, PEG_TOP_Z

__all__ = ["GEOMETRY", "SPEC", "paper_corruption", "NUT_HANDLE_GRIP_X", "PEG_TOP_Z"]

NUT_HANDLE_GRIP_X = 0.062  # [m] where the fingers hold the handle, along the nut's x axis

GEOMETRY = InsertionGeometry(
    held="nut",
    target="peg",
    held_bottom=NUT_HALF_THICKNESS,
    target_top=PEG_HALF[2],
    target_origin_z=PEG_CENTER_Z,
    seat_z=TABLE_TOP_Z,  # the nut goes down the peg to the table
    holding_width=0.036,  # the fingers are on the handle (3.2 cm wide) below this width
    slides_in_xy=0.006,  # 6.75 mm clearance per side: a nut closer than this to the axis slides on
)

SPEC = in_hand_insertion_spec(
    name="nut_insertion",
    instruction="Place the square nut held in the hand onto the square peg.",
    geometry=GEOMETRY,
    boxes=(
        ObjectBox("nut", half_size=(0.0615, 0.04375, NUT_HALF_THICKNESS), center=(0.0178, 0.0, 0.0)),
        ObjectBox("peg", half_size=PEG_HALF),
    ),
)


def paper_corruption() -> BoxNoise:
    """The paper's Nut Insertion error on the peg position: +-4 cm per axis, at least 2 cm in one."""
    return BoxNoise(half_extent=(0.04, 0.04, 0.04), min_abs=(0.02, 0.02, 0.02), require="any")
