"""RatePacer: periods of the wall clock, or of an arm's own clock that may run slower than real time.

Timing tests: they run in the realtime pass (nothing else on the CPU). Tolerances are stated per test.
"""

import time

import pytest

from igen_lerobot.core.pacing import ClockStalledError, RatePacer

pytestmark = pytest.mark.realtime


def _run(pacer: RatePacer, periods: int) -> float:
    start = time.perf_counter()
    for _ in range(periods):
        pacer.wait()
    return time.perf_counter() - start


def test_periods_of_a_clock_at_half_speed_last_twice_as_long_on_the_wall():
    """20 periods at 20 Hz: 1 s of wall time on the wall clock, 2 s on a clock running at half speed
    (a simulator behind the arm's protocol slower than real time). Tolerance: -5% / +25%."""
    wall = _run(RatePacer(20), 20)
    assert 0.95 <= wall <= 1.25, wall
    start = time.perf_counter()
    half_speed = _run(RatePacer(20, clock=lambda: 0.5 * (time.perf_counter() - start)), 20)
    assert 1.9 <= half_speed <= 2.5, half_speed


def test_a_late_tick_starts_the_next_period_instead_of_a_burst():
    """After a 0.3 s stall (6 periods late) the next wait returns at once and later ones pace again,
    on either clock: no burst of short periods to catch up. Tolerance: 10 ms, and 5 periods >= 0.24 s."""
    for clock in (None, time.perf_counter):
        pacer = RatePacer(20, clock=clock)
        pacer.wait()
        time.sleep(0.3)
        assert _run(pacer, 1) < 0.01
        assert _run(pacer, 5) >= 0.24


def test_a_clock_that_stops_raises_instead_of_hanging_the_loop():
    """An arm that stops reporting its time: the wait gives up after stall_timeout of wall time
    (0.2 s here; tolerance +0.3 s) with an error that says so."""
    pacer = RatePacer(20, clock=lambda: 12.5, stall_timeout=0.2)
    start = time.perf_counter()
    with pytest.raises(ClockStalledError, match="stood at 12.500 s for 0.2 s"):
        pacer.wait()
    assert 0.2 <= time.perf_counter() - start <= 0.5
