"""The outcome of one seeded generation attempt."""

from __future__ import annotations

from dataclasses import dataclass, field

from igen_lerobot.core.episode import Episode


@dataclass
class Attempt:
    """A kept episode (``reason is None``), or why the attempt was dropped.

    ``episode`` may be ``None`` for a kept attempt once a worker has spooled it itself (local
    worker processes send back only this small summary); ``steps`` counts simulated steps.
    """

    seed: int
    episode: Episode | None
    reason: str | None
    steps: int
    details: dict = field(default_factory=dict)
    length: int = 0

    def __post_init__(self) -> None:
        if self.episode is not None:
            self.length = self.episode.length

    @property
    def kept(self) -> bool:
        return self.reason is None

    def summary(self) -> Attempt:
        """The same outcome without the episode's arrays (cheap to send between processes)."""
        return Attempt(self.seed, None, self.reason, self.steps, self.details, self.length)
