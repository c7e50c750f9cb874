"""Coffee's static description: importable without MuJoCo or robosuite.

The machine is one fixed body whose origin stands on the table under the pod holder's axis: a base
disc, the holder ring on it (the disc's top is the holder's floor) and the machine's body behind
the holder (+x, away from the robot), its front against the ring.
"""

from igen_lerobot.core.error_models import RadialNoise
from igen_lerobot.core.task import ObjectBox
from lerobot_env_igen.in_hand_insertion_spec import InsertionGeometry, in_hand_insertion_spec
from lerobot_env_igen.panda_spec import TABLE_TOP_Z

# the machine, in its own frame [m]
BASE_RADIUS, BASE_HEIGHT = 0.045, 0.01  # the base disc under the holder; its top is the holder's floor
RING_INNER, RING_WALL, RING_HEIGHT = 0.025, 0.004, 0.025  # the pod holder: a ring of box segments
RING_SEGMENTS = 32
BODY_HALF = (0.03, 0.045, 0.045)  # the machine's body, a box behind the holder, 9 cm tall
BODY_X = RING_INNER + RING_WALL + BODY_HALF[0]  # its front face touches the ring's outside
FLOOR_Z = TABLE_TOP_Z + BASE_HEIGHT  # the holder's floor
RING_TOP_Z = FLOOR_Z + RING_HEIGHT
BODY_TOP_Z = TABLE_TOP_Z + 2 * BODY_HALF[2]  # the machine's highest point
# the pod: a truncated cone (a convex mesh), narrower at the bottom, so it funnels itself in
POD_RADII = (0.0205, 0.022)  # [m] bottom, top
POD_HALF_HEIGHT = 0.025  # [m] 5 cm tall; the pod's origin is its centre
SEATED_XY = 0.005  # [m] success: the pod's axis within 5 mm of the holder's in the table plane ...
SEATED_Z = 0.005  # [m] ... and its bottom at most 5 mm above the holder's floor (not on the rim)

GEOMETRY = InsertionGeometry(
    held="pod",
    target="machine",
    held_bottom=POD_HALF_HEIGHT,
    target_top=RING_TOP_Z - TABLE_TOP_Z,  # the holder's rim (the body, taller, stays below the pod's start)
    target_origin_z=TABLE_TOP_Z,
    seat_z=FLOOR_Z,
    holding_width=0.05,  # the fingers are on the pod (4.4 cm across at the top) below this width
    slides_in_xy=0.004,  # further off the holder's axis, the pod lands on the rim (see the README)
)

SPEC = in_hand_insertion_spec(
    name="coffee",
    instruction="Place the pod held in the hand into the coffee machine's pod holder.",
    geometry=GEOMETRY,
    boxes=(
        ObjectBox("pod", half_size=(POD_RADII[1], POD_RADII[1], POD_HALF_HEIGHT)),
        ObjectBox(
            "machine",
            half_size=((BODY_X + BODY_HALF[0] + BASE_RADIUS) / 2, BODY_HALF[1], BODY_HALF[2]),
            center=((BODY_X + BODY_HALF[0] - BASE_RADIUS) / 2, 0.0, BODY_HALF[2]),
        ),
    ),
)


def paper_corruption() -> RadialNoise:
    """The paper's Coffee error on the machine's position: 2-4 cm in a uniform direction in the table plane."""
    return RadialNoise(r_min=0.02, r_max=0.04, axes=(0, 1))
