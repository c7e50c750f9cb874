"""Crash-safe, resumable storage of finished attempts before they become a LeRobot dataset.

Every attempt (one seeded try at an episode) ends as exactly one file, written atomically:
``attempt_00000042.npz`` (kept) or ``attempt_00000042.rejected.json`` (why it was dropped).
A killed run leaves only whole files, so a resumed run skips what is done and the final dataset
is the first ``N`` kept attempts in attempt order, whatever the order workers finished in.
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from igen_lerobot.core.episode import Episode

_KEPT = re.compile(r"^attempt_(\d{8})\.npz$")
_REJECTED = re.compile(r"^attempt_(\d{8})\.rejected\.json$")


@dataclass(frozen=True)
class GenerationOutcome:
    """What it took to keep the dataset's episodes, counted over the attempts up to its last one.

    Workers run a few attempts past the last one a dataset needs (they were in flight when it
    finished); how many depends on scheduling, so they are counted apart and never in the rate.
    """

    attempted: int  # kept or dropped attempts up to the dataset's last kept one (one that raised is not spooled)
    kept: int
    dropped: dict[str, int]
    run_past_the_last: int  # attempts finished beyond it (scheduling-dependent)

    @property
    def success_rate(self) -> float:
        return self.kept / self.attempted if self.attempted else 0.0


class EpisodeSpool:
    """A directory of attempt results."""

    def __init__(self, directory: Path) -> None:
        self.directory = Path(directory)
        self.directory.mkdir(parents=True, exist_ok=True)
        for stale in self.directory.glob("*.tmp"):  # half-written by a killed process
            stale.unlink()

    def _kept_path(self, attempt: int) -> Path:
        return self.directory / f"attempt_{attempt:08d}.npz"

    def _rejected_path(self, attempt: int) -> Path:
        return self.directory / f"attempt_{attempt:08d}.rejected.json"

    def keep(self, attempt: int, episode: Episode) -> None:
        episode.save(self._kept_path(attempt))

    def reject(self, attempt: int, reason: str, **details: object) -> None:
        path = self._rejected_path(attempt)
        tmp = path.with_name(path.name + ".tmp")
        tmp.write_text(json.dumps({"attempt": attempt, "reason": reason, **details}))
        tmp.replace(path)

    def kept_attempts(self) -> list[int]:
        return sorted(int(m.group(1)) for p in self.directory.iterdir() if (m := _KEPT.match(p.name)))

    def rejected_attempts(self) -> list[int]:
        return sorted(int(m.group(1)) for p in self.directory.iterdir() if (m := _REJECTED.match(p.name)))

    def done_attempts(self) -> set[int]:
        return set(self.kept_attempts()) | set(self.rejected_attempts())

    def rejection_reasons(self, before: int | None = None) -> dict[str, int]:
        """Why attempts were dropped, counted per reason (only attempts numbered below ``before``, if given)."""
        counts: dict[str, int] = {}
        for attempt in self.rejected_attempts():
            if before is not None and attempt >= before:
                continue
            reason = json.loads(self._rejected_path(attempt).read_text())["reason"]
            counts[reason] = counts.get(reason, 0) + 1
        return counts

    def outcome(self, num_episodes: int) -> GenerationOutcome:
        """Counts behind the first ``num_episodes`` kept attempts: the same for any worker count."""
        kept = self.kept_attempts()[:num_episodes]
        last = kept[-1] if kept else -1
        dropped = self.rejection_reasons(before=last)
        beyond = sum(1 for attempt in self.done_attempts() if attempt > last)
        attempted = len(kept) + sum(dropped.values())
        return GenerationOutcome(attempted=attempted, kept=len(kept), dropped=dropped, run_past_the_last=beyond)

    def load(self, attempt: int) -> Episode:
        return Episode.load(self._kept_path(attempt))

    def iter_kept(self, limit: int | None = None) -> Iterator[tuple[int, Episode]]:
        """Kept episodes in attempt order, loaded one at a time (memory stays flat)."""
        for i, attempt in enumerate(self.kept_attempts()):
            if limit is not None and i >= limit:
                return
            yield attempt, self.load(attempt)
