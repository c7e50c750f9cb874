"""The in-hand insertion family's env: a part held in the hand goes into (onto) a fixed target.

At reset the target is placed uniformly in the config's region, then the task puts its part in the
closed fingers at the home pose (:meth:`InHandInsertionEnv.place_in_hand`) and the fingers get a
few control periods to settle on it. Success is the task's own test that the part is in
(:meth:`InHandInsertionEnv.inserted`) **and released**: no part of the hand touches it, since a
part still held can already pass an "in" test.
"""

from __future__ import annotations

import abc
from typing import TYPE_CHECKING

import numpy as np

from lerobot_env_igen.panda import TOP_DOWN_ROT
from lerobot_env_igen.panda_spec import GRIPPER
from lerobot_env_igen.panda_task import PandaTaskEnv
from lerobot_env_igen.placement import RegionPlacer

if TYPE_CHECKING:
    from lerobot_env_igen.config_in_hand_insertion import InHandInsertionEnvConfig

SETTLE_STEPS = 5  # control periods the closed fingers get to settle on the held part at reset


class InHandInsertionEnv(PandaTaskEnv):
    """An in-hand insertion task on the compiled robosuite Panda scene."""

    def __init__(
        self,
        config: InHandInsertionEnvConfig,
        held_object,
        target_object,
        home_pos: tuple[float, float, float],
    ) -> None:
        """``held_object``, ``target_object``: robosuite objects (the target fixed: ``joints=None``)."""
        super().__init__(config, objects=[held_object, target_object], home_pos=home_pos)
        self.geometry = config.geometry
        self.target_placer = RegionPlacer(self.geometry.target, config.region(), z=self.geometry.target_origin_z)

    def place(self, rng: np.random.Generator) -> None:
        self.target_placer.place(self, rng)
        self.place_in_hand(rng)

    @abc.abstractmethod
    def place_in_hand(self, rng: np.random.Generator) -> None:
        """Put the held part between the fingers at the home pose and hold them closed (``arm.hold_closed``)."""

    def settle(self) -> None:
        home = self.arm.eef_pos()
        for _ in range(SETTLE_STEPS):
            self.arm.control_period(home, True, TOP_DOWN_ROT)

    # ------------------------------------------------------------------ judges
    @abc.abstractmethod
    def inserted(self) -> bool:
        """The held part is in (on) the target, whether or not the hand still holds it."""

    def released(self) -> bool:
        """No part of the hand touches the held part."""
        return not self.parts_in_contact(GRIPPER, self.geometry.held)

    def is_success(self) -> bool:
        return self.inserted() and self.released()
