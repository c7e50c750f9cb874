"""Coffee: a held pod into a coffee machine's pod holder whose observed position is wrong until touched.

Paper setup (IntervenGen, Experiment Setup): a pod goes into a coffee machine's pod holder, the
machine is sampled in a 10 x 10 cm region and its observed position is off by 2-4 cm in a uniform
direction in the table plane; contact reveals the true machine pose (the paper has no partial
variant for Coffee). 6-DOF delta-pose actions at 20 Hz.

* The machine is built from robosuite's composite-object primitive (no MimicGen code or meshes),
  one fixed body: a base disc, the pod holder on it (a ring of 32 box segments, 2.5 cm inner
  radius, 4 mm wall, 2.5 cm tall; the disc's top is its floor) and the machine's body, a 9 cm tall
  box behind the holder (+x), its front against the ring.
* The pod is a truncated cone, 2.05 cm radius at the bottom and 2.2 cm at the top, 5 cm tall: the
  taper funnels a pod a few millimetres off the holder's axis in. It starts **in the hand**, the
  fingers closed across its upper part at the home pose (the paper does not say; one object-centric
  subtask, as its noise model implies), its bottom 4 cm above the machine's top.
* Reveal: a contact of the pod with **any** geom of the machine, not only the holder. The holder
  stands against the body, so a pod erring towards the body lands on the body first; a person
  watching would take any touch of the machine as the sign that the machine is elsewhere, and
  waiting for a holder contact that may never come would hide the mistake.
* Success: the pod's axis within 5 mm of the holder's, its bottom at most 5 mm above the holder's
  floor (a pod jammed on the rim is above it, though its axis may be close) **and released** (no
  finger touches it).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from lerobot_env_igen.coffee.spec import (
    BASE_HEIGHT,
    BASE_RADIUS,
    BODY_HALF,
    BODY_X,
    FLOOR_Z,
    POD_HALF_HEIGHT,
    POD_RADII,
    RING_HEIGHT,
    RING_INNER,
    RING_SEGMENTS,
    RING_WALL,
    SEATED_XY,
    SEATED_Z,
)
from lerobot_env_igen.in_hand_insertion import InHandInsertionEnv
from lerobot_env_igen.panda_spec import PAD_ABOVE_GRIP

if TYPE_CHECKING:
    from lerobot_env_igen.coffee.config import CoffeeEnvConfig

HOME_EEF_POS = (0.0, 0.0, 0.974)  # [m] the pod over the region's centre, its bottom 4 cm above the machine
GRIP_ABOVE_ORIGIN = POD_HALF_HEIGHT - 0.01  # [m] the pads' centres 1 cm below the pod's top
POD_DENSITY = 300.0  # [kg/m^3] about 21 g
POD_EDGES = 24  # vertices on each of the cone's two circles
# a stiff plastic pod: MuJoCo's default contact lets the closed fingers sink 4 mm into the cone, this 1.5 mm
POD_CONTACT = {"solimp": "0.95 0.99 0.001", "solref": "0.01 1"}
POD_RGBA = (0.75, 0.2, 0.15, 1.0)
MACHINE_RGBA = ((0.2, 0.2, 0.22, 1.0), (0.6, 0.6, 0.65, 1.0), (0.3, 0.3, 0.33, 1.0))  # base, holder, body


def pod():
    """A truncated cone: robosuite's composite object with one convex mesh geom, its origin at the centre."""
    import xml.etree.ElementTree as ET

    from robosuite.models.objects import CompositeObject
    from robosuite.utils.mjcf_utils import new_geom

    angles = np.linspace(0.0, 2 * np.pi, POD_EDGES, endpoint=False)
    circles = [(r, z) for r, z in zip(POD_RADII, (-POD_HALF_HEIGHT, POD_HALF_HEIGHT), strict=True)]
    vertex = " ".join(f"{r * np.cos(a):.5f} {r * np.sin(a):.5f} {z:.5f}" for r, z in circles for a in angles)

    class Pod(CompositeObject):
        def _get_object_subtree(self):
            body = super()._get_object_subtree()  # the root body, with no primitive geoms
            self.asset.append(ET.Element("mesh", name="pod_cone", vertex=vertex))
            collision = {**self.get_collision_attrib_template(), "density": str(POD_DENSITY), **POD_CONTACT}
            body.append(new_geom(name="cone", type="mesh", size=None, mesh="pod_cone", **collision))
            visual = {**self.get_visual_attrib_template(), "rgba": POD_RGBA}
            body.append(new_geom(name="cone_vis", type="mesh", size=None, mesh="pod_cone", **visual))
            return body

    half = (POD_RADII[1], POD_RADII[1], POD_HALF_HEIGHT)
    return Pod(name="pod", total_size=half, geom_types=(), geom_sizes=(), geom_locations=())


def machine():
    """The fixed machine from robosuite's composite-object primitive: base disc, holder ring, body."""
    from robosuite.models.objects import CompositeObject

    step = 2 * np.pi / RING_SEGMENTS
    half_across = (RING_INNER + RING_WALL) * np.tan(step / 2)  # segments meet at the outside
    mid = RING_INNER + RING_WALL / 2
    ring_z = BASE_HEIGHT + RING_HEIGHT / 2
    angles = step * np.arange(RING_SEGMENTS)
    types = ["cylinder", *["box"] * RING_SEGMENTS, "box"]
    segment = (RING_WALL / 2, half_across, RING_HEIGHT / 2)
    sizes = [(BASE_RADIUS, BASE_HEIGHT / 2), *[segment] * RING_SEGMENTS, BODY_HALF]
    locations = [
        (0.0, 0.0, BASE_HEIGHT / 2),
        *[(mid * np.cos(a), mid * np.sin(a), ring_z) for a in angles],
        (BODY_X, 0.0, BODY_HALF[2]),
    ]
    quats = [None, *[(np.cos(a / 2), 0.0, 0.0, np.sin(a / 2)) for a in angles], None]
    names = ["base", *[f"holder{k}" for k in range(RING_SEGMENTS)], "body"]
    rgbas = [MACHINE_RGBA[0], *[MACHINE_RGBA[1]] * RING_SEGMENTS, MACHINE_RGBA[2]]
    return CompositeObject(
        name="machine",
        total_size=(BODY_X + BODY_HALF[0], BODY_HALF[1], BODY_HALF[2]),
        geom_types=types,
        geom_sizes=sizes,
        geom_locations=locations,
        geom_quats=quats,
        geom_names=names,
        geom_rgbas=rgbas,
        locations_relative_to_center=True,
        joints=None,
    )


class CoffeeEnv(InHandInsertionEnv):
    """The Coffee task on the compiled robosuite Panda scene."""

    def __init__(self, config: CoffeeEnvConfig) -> None:
        super().__init__(config, pod(), machine(), HOME_EEF_POS)

    def place_in_hand(self, rng: np.random.Generator) -> None:
        # fingers across the pod's upper part, the pads 1 cm below its top
        centre = self.arm.eef_pos() + np.array([0.0, 0.0, PAD_ABOVE_GRIP - GRIP_ABOVE_ORIGIN])
        self.set_free_pose("pod", centre)
        radius = np.interp(GRIP_ABOVE_ORIGIN, (-POD_HALF_HEIGHT, POD_HALF_HEIGHT), POD_RADII)  # the taper's
        self.arm.hold_closed(float(radius) + 0.0006)

    # ------------------------------------------------------------------ judges
    def seated(self) -> bool:
        """The pod's axis over the holder's and its bottom down at the holder's floor (not on the rim)."""
        pod = self.data.xpos[self.bodies["pod"]]
        holder = self.data.xpos[self.bodies["machine"]]
        near = float(np.linalg.norm(pod[:2] - holder[:2])) < SEATED_XY
        return bool(near and pod[2] - POD_HALF_HEIGHT <= FLOOR_Z + SEATED_Z)

    def inserted(self) -> bool:
        return self.seated()
