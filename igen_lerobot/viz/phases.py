"""What each frame of an episode was, as a colour: the vocabulary every view shares.

From the per-frame ``frame_source`` and the ``revealed`` flag of the observation:

* demonstration (grey): an operator or a generated demonstration, not an intervention;
* policy (blue): the robot's policy acting on its belief;
* mistake (red): policy frames after the first contact revealed the belief was wrong, until
  someone takes over (in a kept intervention these lead into the recovery);
* operator recovery (green): a person or the scripted operator in control, flagged;
* generated recovery (orange): a transformed source segment replayed by the generator, flagged;
* interpolation (yellow): the generator's bridge into a transformed recovery, flagged.

The three recovery colours are exactly the frames flagged ``is_intervention``.
"""

from __future__ import annotations

import enum

import numpy as np

from igen_lerobot.core.task import FrameSource


class Phase(enum.IntEnum):
    """A frame's role; stored as ints, coloured by ``PHASE_COLORS``."""

    POLICY = 0
    MISTAKE = 1
    OPERATOR = 2
    GENERATED = 3
    INTERPOLATION = 4
    DEMO = 5


PHASE_COLORS = {
    Phase.POLICY: (66, 133, 244),
    Phase.MISTAKE: (219, 68, 55),
    Phase.OPERATOR: (15, 157, 88),
    Phase.GENERATED: (255, 140, 0),
    Phase.INTERPOLATION: (244, 205, 0),
    Phase.DEMO: (150, 150, 150),
}
PHASE_LABELS = {
    Phase.POLICY: "policy",
    Phase.MISTAKE: "policy after a mistake",
    Phase.OPERATOR: "operator recovery",
    Phase.GENERATED: "generated recovery",
    Phase.INTERPOLATION: "interpolation",
    Phase.DEMO: "demonstration",
}
RECOVERY_PHASES = (Phase.OPERATOR, Phase.GENERATED, Phase.INTERPOLATION)


def frame_phases(source: np.ndarray, flagged: np.ndarray, revealed: np.ndarray) -> np.ndarray:
    """Phase (int) of every frame from ``frame_source``, ``is_intervention`` and the latched ``revealed``.

    ``revealed`` comes from the observation (:meth:`~igen_lerobot.core.task.TaskSpec.revealed_flags`).
    """
    source = np.asarray(source).reshape(-1)
    flagged = np.asarray(flagged, dtype=bool).reshape(-1)
    revealed = np.asarray(revealed, dtype=bool).reshape(-1)
    policy = source == FrameSource.POLICY
    phases = np.full(source.shape, int(Phase.DEMO))
    phases[policy] = Phase.POLICY
    phases[policy & revealed] = Phase.MISTAKE
    phases[flagged & (source == FrameSource.OPERATOR)] = Phase.OPERATOR
    phases[flagged & (source == FrameSource.GENERATED)] = Phase.GENERATED
    phases[flagged & (source == FrameSource.INTERPOLATION)] = Phase.INTERPOLATION
    return phases


def phase_colors(phases: np.ndarray) -> np.ndarray:
    """(N, 3) uint8 colours of ``phases``."""
    table = np.array([PHASE_COLORS[Phase(i)] for i in range(len(Phase))], dtype=np.uint8)
    return table[np.asarray(phases, dtype=int)]


def believed_before_reveal(believed: np.ndarray, true: np.ndarray, corruption: np.ndarray, revealed: np.ndarray):
    """Per frame, the corrupted object's pose (N, 7) as the robot believed it before any reveal.

    The dataset's belief column says what the robot believed at each frame, so it already equals
    the truth from the first frame of an episode that starts revealed (a generated recovery starts
    at the contact). Views want to show where the mistake came from: for such an episode, the true
    first pose moved by the episode's position error (``corruption``, 3 numbers); otherwise the
    first frame's belief. Other error models (a flipped handle) keep the first frame's belief.
    """
    before = np.array(believed[0] if not revealed[0] or len(corruption) != 3 else true[0], dtype=float)
    if revealed[0] and len(corruption) == 3:
        before[:3] += np.asarray(corruption, dtype=float)
    return np.tile(before, (len(believed), 1))
