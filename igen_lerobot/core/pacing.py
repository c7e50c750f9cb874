"""Real-time pacing for loops with a person or a robot in them."""

from __future__ import annotations

import time
from collections.abc import Callable

from igen_lerobot.core.exceptions import IgenError


class ClockStalledError(IgenError, TimeoutError):
    """The clock a loop is paced on stopped advancing (an arm that no longer reports its time)."""


class RatePacer:
    """Keeps a loop at ``hz`` when a person or a robot is in it (``None``: as fast as possible).

    ``clock``: the clock whose periods count (default: the wall clock). A robot's own clock
    (libfranka's robot time) makes a period the arm's 50 ms even where a simulator behind the
    protocol runs slower than real time (it must not run faster: the wait sleeps what is left of
    the period on it, then reads it again); a clock that stands still for
    ``stall_timeout`` seconds of wall time raises :class:`ClockStalledError` instead of hanging the loop.
    A late tick is not made up with a burst of short periods: the next period starts from it.
    """

    def __init__(self, hz: float | None, clock: Callable[[], float] | None = None, stall_timeout: float = 1.0) -> None:
        self.period = None if not hz else 1.0 / hz
        self.clock = clock
        self.stall_timeout = stall_timeout
        self._next = (clock or time.perf_counter)() if self.period is not None else 0.0

    def wait(self) -> None:
        if self.period is None:
            return
        self._next += self.period
        if self.clock is None:
            delay = self._next - time.perf_counter()
            if delay > 0:
                time.sleep(delay)
            else:
                self._next = time.perf_counter()
            return
        deadline = time.perf_counter() + self.stall_timeout
        now = self.clock()
        if now >= self._next:
            self._next = now
            return
        while now < self._next:
            if time.perf_counter() > deadline:
                raise ClockStalledError(
                    f"the loop's clock stood at {now:.3f} s for {self.stall_timeout} s of wall time"
                )
            # an arm's clock runs no faster than the wall clock: sleeping what is left of the period
            # never overshoots, and a slower clock is polled a few times a period, not every millisecond
            time.sleep(max(self._next - now, 0.0005))
            now = self.clock()
