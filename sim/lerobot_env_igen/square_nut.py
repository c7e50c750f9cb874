"""robosuite's square nut and square peg, shared by Nut Insertion and Nut-and-Peg Assembly.

The nut (``models/assets/objects/square-nut.xml``, MIT): a square ring 8.75 cm outside with a
4.55 cm hole, 2 cm thick, and a handle box from 2.875 cm to 7.925 cm out along the nut's x axis,
3.175 cm wide (along its y axis). The peg: a fixed 3.2 x 3.2 cm box 13 cm tall (robosuite's
``peg1`` width). Importable without MuJoCo or robosuite: those load when a model is built.
"""

from __future__ import annotations

import numpy as np

from lerobot_env_igen.panda_spec import TABLE_TOP_Z

NUT_HALF_THICKNESS = 0.01  # [m]
NUT_RING_HALF = 0.04375  # [m] half the ring's outside width
HANDLE_HALF_WIDTH = 0.015875  # [m] the handle's half width, along the nut's y axis
HANDLE_END_X = 0.07925  # [m] the handle's far end along the nut's x axis
PEG_HALF = (0.016, 0.016, 0.065)  # [m] a 3.2 x 3.2 cm peg standing 13 cm tall
PEG_CENTER_Z = TABLE_TOP_Z + PEG_HALF[2]
PEG_TOP_Z = TABLE_TOP_Z + 2 * PEG_HALF[2]
PEG_RGBA = (0.55, 0.55, 0.6, 1.0)
ON_PEG_XY = 0.03  # [m] robosuite's on_peg: nut centre within 3 cm of the peg axis in x and y ...
ON_PEG_Z = 0.05  # [m] ... and below the table top + 5 cm


def square_nut(name: str = "nut"):
    """Robosuite's square nut (its model and meshes ship with robosuite, MIT)."""
    from robosuite.models.objects import SquareNutObject

    return SquareNutObject(name=name)


def square_peg(name: str = "peg"):
    """The fixed square peg (a robosuite box, moved only at reset)."""
    from lerobot_env_igen.scene import box

    return box(name, PEG_HALF, PEG_RGBA, fixed=True)


def on_peg(nut_pos: np.ndarray, peg_pos: np.ndarray) -> bool:
    """Robosuite's ``on_peg``: the nut centre near the peg axis [m] and down at the table (world positions)."""
    near = abs(nut_pos[0] - peg_pos[0]) < ON_PEG_XY and abs(nut_pos[1] - peg_pos[1]) < ON_PEG_XY
    return bool(near and nut_pos[2] < TABLE_TOP_Z + ON_PEG_Z)
