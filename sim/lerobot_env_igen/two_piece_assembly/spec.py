"""2-Piece Assembly's static description: importable without MuJoCo or robosuite."""

from igen_lerobot.core.error_models import BoxNoise
from igen_lerobot.core.task import ObjectBox
from lerobot_env_igen.in_hand_insertion_spec import InsertionGeometry, in_hand_insertion_spec
from lerobot_env_igen.panda_spec import TABLE_TOP_Z

# the receptacle: robosuite's Bin, 12.6 cm square outside, 6 mm walls and floor, 4 cm tall
RECEPTACLE_SIZE = (0.126, 0.126, 0.04)  # [m] full outside size
RECEPTACLE_WALL = 0.006  # [m] wall and floor thickness
RECEPTACLE_CENTER_Z = TABLE_TOP_Z + RECEPTACLE_SIZE[2] / 2  # its origin is its box's centre
FLOOR_Z = TABLE_TOP_Z + RECEPTACLE_WALL  # the inside floor
# the piece: a square slab 6 mm narrower than the inside on each side, with a ridge on top to hold
SLAB_HALF = (0.051, 0.051, 0.006)  # [m] 10.2 x 10.2 x 1.2 cm; the piece's origin is the slab's centre
RIDGE_HALF = (0.03, 0.01, 0.015)  # [m] 6 cm long (world x), 2 cm across the fingers, 3 cm tall
RIDGE_CENTER_Z = SLAB_HALF[2] + RIDGE_HALF[2]  # [m] above the piece's origin
SEATED_XY = 0.01  # [m] success: the piece's centre within 1 cm of the receptacle's in the table plane ...
SEATED_Z = 0.005  # [m] ... and its bottom at most 5 mm above the floor (not resting on the rim)

GEOMETRY = InsertionGeometry(
    held="piece",
    target="receptacle",
    held_bottom=SLAB_HALF[2],
    target_top=RECEPTACLE_SIZE[2] / 2,
    target_origin_z=RECEPTACLE_CENTER_Z,
    seat_z=FLOOR_Z,  # the slab goes down to the receptacle's floor
    holding_width=0.024,  # the fingers are on the ridge (2 cm across) below this width
    slides_in_xy=0.006,  # 6 mm clearance per side: further off, the slab lands on the rim
)

SPEC = in_hand_insertion_spec(
    name="two_piece_assembly",
    instruction="Place the piece held in the hand into the square receptacle.",
    geometry=GEOMETRY,
    boxes=(
        ObjectBox(
            "piece",
            half_size=(SLAB_HALF[0], SLAB_HALF[1], SLAB_HALF[2] + RIDGE_HALF[2]),
            center=(0.0, 0.0, RIDGE_HALF[2]),
        ),
        ObjectBox("receptacle", half_size=tuple(s / 2 for s in RECEPTACLE_SIZE)),
    ),
)


def paper_corruption() -> BoxNoise:
    """The paper's 2-Piece Assembly error on the receptacle position: +-4 cm per axis, at least 1 cm in one."""
    return BoxNoise(half_extent=(0.04, 0.04, 0.04), min_abs=(0.01, 0.01, 0.01), require="any")
