"""Real-time pacing for loops with a person or a robot in them."""

from __future__ import annotations

import time


class RatePacer:
    """Keeps a loop at ``hz`` when a person is in it (``None``: as fast as possible)."""

    def __init__(self, hz: float | None) -> None:
        self.period = None if not hz else 1.0 / hz
        self._next = time.perf_counter()

    def wait(self) -> None:
        if self.period is None:
            return
        self._next += self.period
        delay = self._next - time.perf_counter()
        if delay > 0:
            time.sleep(delay)
        else:
            self._next = time.perf_counter()
