"""2-Piece Assembly: a held piece into a square receptacle whose observed position is wrong until touched.

Paper setup (IntervenGen, Experiment Setup): an object goes into a square receptacle with a
narrow affordance region, the receptacle is sampled in a 10 x 10 cm region, its observed position
is off by up to 4 cm per axis with at least 1 cm in one, and the piece-receptacle contact reveals
the true receptacle pose (``--env.reveal=direction``: only the unit vector in the table plane from
the believed to the true position). 6-DOF delta-pose actions at 20 Hz.

* The receptacle is robosuite's ``Bin`` (12.6 cm square outside, 6 mm walls and floor, 4 cm tall),
  fixed. The piece is a 10.2 cm square slab, 1.2 cm thick, with a ridge on top: 6 mm of clearance
  per side, so a piece more than that off the receptacle's axis lands on the rim.
* The piece starts in the hand, the fingers closed across its ridge, its yaw aligned with the
  receptacle's (the paper does not say; one object-centric subtask, as its noise model implies).
* Success: the piece's centre within 1 cm of the receptacle's in x and y, its bottom at most 5 mm
  above the floor (a piece resting on the rim is above it) **and released** (no finger touches it).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from lerobot_env_igen.in_hand_insertion import InHandInsertionEnv
from lerobot_env_igen.panda_spec import PAD_ABOVE_GRIP
from lerobot_env_igen.two_piece_assembly.spec import (
    FLOOR_Z,
    RECEPTACLE_SIZE,
    RECEPTACLE_WALL,
    RIDGE_CENTER_Z,
    RIDGE_HALF,
    SEATED_XY,
    SEATED_Z,
    SLAB_HALF,
)

if TYPE_CHECKING:
    from lerobot_env_igen.two_piece_assembly.config import TwoPieceAssemblyEnvConfig

HOME_EEF_POS = (0.0, 0.0, 0.935)  # [m] the piece over the region's centre, its bottom 6.6 cm above the rim
GRIP_ABOVE_ORIGIN = RIDGE_CENTER_Z + 0.005  # [m] the pads' centres above the piece's origin (upper ridge)
PIECE_DENSITY = 400.0  # [kg/m^3] about 64 g
PIECE_RGBA = ((0.2, 0.45, 0.8, 1.0), (0.9, 0.6, 0.1, 1.0))  # slab, ridge
RECEPTACLE_RGBA = (0.55, 0.55, 0.6, 1.0)


def piece():
    """A slab with a ridge on top, from robosuite's composite-object primitive; its origin is the slab's centre."""
    from robosuite.models.objects import CompositeObject

    return CompositeObject(
        name="piece",
        total_size=(SLAB_HALF[0], SLAB_HALF[1], SLAB_HALF[2] + RIDGE_HALF[2]),
        geom_types=("box", "box"),
        geom_sizes=(SLAB_HALF, RIDGE_HALF),
        geom_locations=((0.0, 0.0, 0.0), (0.0, 0.0, RIDGE_CENTER_Z)),
        geom_names=("slab", "ridge"),
        geom_rgbas=PIECE_RGBA,
        density=PIECE_DENSITY,
        locations_relative_to_center=True,
    )


def receptacle():
    """The receptacle: robosuite's ``Bin`` (MIT) fixed to the table, an open-topped box; its origin is its centre."""
    from robosuite.models.objects import Bin

    class FixedBin(Bin):
        def _get_geom_attrs(self) -> dict:
            return {**super()._get_geom_attrs(), "joints": None}

    return FixedBin(
        name="receptacle",
        bin_size=RECEPTACLE_SIZE,
        wall_thickness=RECEPTACLE_WALL,
        transparent_walls=False,
        use_texture=False,
        rgba=RECEPTACLE_RGBA,
    )


class TwoPieceAssemblyEnv(InHandInsertionEnv):
    """The 2-Piece Assembly task on the compiled robosuite Panda scene."""

    def __init__(self, config: TwoPieceAssemblyEnvConfig) -> None:
        super().__init__(config, piece(), receptacle(), HOME_EEF_POS)

    def place_in_hand(self, rng: np.random.Generator) -> None:
        # fingers across the ridge (the ridge runs along world x), the pads on its upper part
        centre = self.arm.eef_pos() + np.array([0.0, 0.0, PAD_ABOVE_GRIP - GRIP_ABOVE_ORIGIN])
        self.set_free_pose("piece", centre)
        self.arm.hold_closed(RIDGE_HALF[1] + 0.0006)

    # ------------------------------------------------------------------ judges
    def seated(self) -> bool:
        """The piece's centre over the receptacle's and its bottom down at the floor (not on the rim)."""
        piece = self.data.xpos[self.bodies["piece"]]
        target = self.data.xpos[self.bodies["receptacle"]]
        near = float(np.linalg.norm(piece[:2] - target[:2])) < SEATED_XY
        return bool(near and piece[2] - SLAB_HALF[2] <= FLOOR_Z + SEATED_Z)

    def inserted(self) -> bool:
        return self.seated()
