"""franky-sim for the franky backend's tests: :mod:`lerobot_robot_igen.arm.franky_sim_server` on a
fresh loopback address per server, so that parallel test runs do not share a robot."""

from __future__ import annotations

from contextlib import contextmanager

from lerobot_robot_igen.arm.franky_sim_server import AddressTakenError, free_loopback, start, stop

__all__ = ["AddressTakenError", "franky_sim", "free_loopback", "stop"]

BIND_ATTEMPTS = 5


@contextmanager
def franky_sim(cube: tuple[float, float] | None = (0.5, 0.0), timeout: float = 60.0, scene_port: int | None = None):
    """Yield the running franky-sim server (``.host``; ``.scene_port`` when asked for); kill it afterwards.

    An address whose ports are still held (by a server killed a moment ago, or another run's) is
    replaced by a fresh one, up to BIND_ATTEMPTS times.
    """
    for attempt in range(1, BIND_ATTEMPTS + 1):
        try:
            proc = start(free_loopback(), cube, scene_port, timeout)
            break
        except AddressTakenError:
            if attempt == BIND_ATTEMPTS:
                raise
    try:
        yield proc
    finally:
        stop(proc)
        proc.log.unlink(missing_ok=True)
