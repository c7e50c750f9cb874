"""Start and stop franky-sim (a libfranka-protocol FR3 simulator) for the franky backend's tests.

franky-sim needs mujoco 4, so it lives in its own environment (tools/franky_sim/.venv, made by
scripts/setup.sh); the server runs there as a subprocess on a loopback address of its own, so
that parallel test runs do not share a robot.
"""

from __future__ import annotations

import os
import random
import signal
import subprocess
import time
from contextlib import contextmanager
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PYTHON = ROOT / "tools" / "franky_sim" / ".venv" / "bin" / "python"
SERVE = ROOT / "tools" / "franky_sim" / "serve.py"


BIND_ATTEMPTS = 5
ADDRESS_TAKEN = ("Could not find available hostname", "Address already in use")  # franky-sim's, the scene port's


def free_loopback() -> str:
    """A random loopback address, so that servers of parallel runs do not meet (libfranka's ports are fixed)."""
    rng = random.SystemRandom()
    return f"127.0.{rng.randint(20, 250)}.{rng.randint(20, 250)}"


class AddressTakenError(RuntimeError):
    """franky-sim could not bind its ports on the address it was given."""


@contextmanager
def franky_sim(cube: tuple[float, float] | None = (0.5, 0.0), timeout: float = 60.0, scene_port: int | None = None):
    """Yield the running franky-sim server (``.host``; ``.scene_port`` when asked for); kill it afterwards.

    An address whose ports are still held (by a server killed a moment ago, or another run's) is
    replaced by a fresh one, up to BIND_ATTEMPTS times.
    """
    if not PYTHON.exists():
        raise RuntimeError(f"franky-sim's environment is missing ({PYTHON}); run `make setup` (scripts/setup.sh)")
    for attempt in range(1, BIND_ATTEMPTS + 1):
        try:
            proc = _start(free_loopback(), cube, timeout, scene_port)
            break
        except AddressTakenError:
            if attempt == BIND_ATTEMPTS:
                raise
    try:
        yield proc
    finally:
        stop(proc)


def _start(host: str, cube: tuple[float, float] | None, timeout: float, scene_port: int | None) -> subprocess.Popen:
    """Start franky-sim on ``host`` and return it once it says READY."""
    command = [str(PYTHON), str(SERVE), "--hostname", host]
    if cube is not None:
        command += ["--cube", str(cube[0]), str(cube[1])]
    if scene_port is not None:
        command += ["--scene-port", str(scene_port)]
    proc = subprocess.Popen(
        command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True
    )
    try:
        deadline = time.monotonic() + timeout
        lines = []
        while time.monotonic() < deadline:
            line = proc.stdout.readline()
            if not line and proc.poll() is not None:
                break
            lines.append(line)
            if line.startswith("READY"):
                break
        else:
            raise RuntimeError("franky-sim did not start in time:\n" + "".join(lines))
        if proc.poll() is not None:
            output = "".join(lines)
            error = AddressTakenError if any(m in output for m in ADDRESS_TAKEN) else RuntimeError
            raise error("franky-sim exited:\n" + output)
    except BaseException:
        stop(proc)
        raise
    proc.host = host
    proc.scene_port = scene_port
    return proc


def stop(proc: subprocess.Popen) -> None:
    """Kill the server (and anything it started) and wait for it."""
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGKILL)
    proc.wait(timeout=10)
