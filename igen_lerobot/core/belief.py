"""What the robot believes about an object's pose, and what a contact reveals.

One model for every task and for the real robot: the simulated tasks and ``igen-deploy`` both
keep an :class:`ObjectBelief` per corrupted object and feed it the task's reveal contact.
Before that contact the robot believes the error model's pose; the first contact is the
mistake the paper's operator (and our generator) reacts to, and from then on the reveal mode
decides what the robot knows:

* ``none``: nothing; the belief stays wrong for the whole episode;
* ``full``: the true pose (the paper's main setting);
* ``contact_position``: the mean position of the first contact replaces the believed position
  (Nut Insertion's partial observability; on a real arm: where the hand was when it felt it);
* ``direction``: the belief stays wrong, and a unit vector in the table plane from the believed
  to the true position at first contact becomes observable (2-Piece Assembly's partial variant).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

import numpy as np

from igen_lerobot.core.error_models import ErrorModel

__all__ = ["Reveal", "ObjectBelief", "REVEAL_HINT_NAMES"]


class Reveal(enum.StrEnum):
    """What the robot learns about the corrupted object's pose on its first reveal contact."""

    NONE = "none"
    FULL = "full"
    CONTACT_POSITION = "contact_position"
    DIRECTION = "direction"


# observation values a reveal mode adds after the task's own (per corrupted object)
REVEAL_HINT_NAMES: dict[Reveal, tuple[str, ...]] = {Reveal.DIRECTION: ("dir.x", "dir.y", "dir.z")}


@dataclass
class ObjectBelief:
    """The belief about one object during one episode."""

    error_model: ErrorModel
    sample: np.ndarray
    reveal: Reveal = Reveal.FULL
    revealed: bool = False
    contact: bool = False
    contact_position: np.ndarray | None = None  # [m] where the revealing contact was
    direction: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self) -> None:
        self.reveal = Reveal(self.reveal)
        self.sample = self.error_model.checked(self.sample)

    def update(self, contact: bool, contact_position: np.ndarray | None, T_world_obj: np.ndarray | None) -> bool:
        """Take this period's reveal-contact signal; True on the contact that reveals (the mistake).

        ``contact_position`` is where the contact was (the mean contact point in simulation, the
        hand's position on a real arm); ``T_world_obj`` is the object's true (or perceived) pose,
        needed only by the contact that reveals.
        """
        self.contact = bool(contact)
        if not self.contact or self.revealed:
            return False
        if T_world_obj is None:
            raise ValueError("the contact that reveals needs the object's true pose")
        self.revealed = True
        believed = self.error_model.apply(T_world_obj, self.sample)
        self.contact_position = (
            np.array(contact_position, dtype=float) if contact_position is not None else believed[:3, 3].copy()
        )
        towards = np.asarray(T_world_obj, dtype=float)[:3, 3] - believed[:3, 3]
        towards[2] = 0.0
        norm = float(np.linalg.norm(towards))
        self.direction = towards / norm if norm > 1e-9 else np.zeros(3)
        return True

    def believed_pose(self, T_world_obj: np.ndarray) -> np.ndarray:
        """``T_world_obj`` as the robot believes it, given the true (or perceived) pose."""
        if not self.revealed or self.reveal in (Reveal.NONE, Reveal.DIRECTION):
            return self.error_model.apply(T_world_obj, self.sample)
        if self.reveal is Reveal.FULL:
            return np.array(T_world_obj, dtype=float)
        believed = self.error_model.apply(T_world_obj, self.sample)
        believed[:3, 3] = self.contact_position
        return believed

    def hint(self) -> np.ndarray:
        """The extra observation values of the reveal mode (``REVEAL_HINT_NAMES``); empty if it has none."""
        if self.reveal is Reveal.DIRECTION:
            return self.direction.copy() if self.revealed else np.zeros(3)
        return np.zeros(0)
