"""Start and stop franky-sim (a libfranka-protocol FR3 simulator) for rehearsals through the franky backend.

franky-sim needs mujoco 4, so it lives in its own environment (``tools/franky_sim/.venv``, made by
``scripts/setup.sh``) and runs as a subprocess on a loopback address: libfranka's ports are fixed,
so two servers on one machine need two addresses. ``igen-rehearse`` and the tests start it here.
"""

from __future__ import annotations

import os
import random
import signal
import subprocess
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[3]
PYTHON = REPO_ROOT / "tools" / "franky_sim" / ".venv" / "bin" / "python"
SERVE = REPO_ROOT / "tools" / "franky_sim" / "serve.py"
ADDRESS_TAKEN = ("Could not find available hostname", "Address already in use")  # franky-sim's, the scene port's


class AddressTakenError(RuntimeError):
    """franky-sim could not bind its ports on the address it was given."""


def free_loopback() -> str:
    """A random loopback address, so that servers of parallel runs do not meet (libfranka's ports are fixed)."""
    rng = random.SystemRandom()
    return f"127.0.{rng.randint(20, 250)}.{rng.randint(20, 250)}"


def start(
    host: str,
    cube: tuple[float, float] | None = (0.5, 0.0),
    scene_port: int | None = None,
    timeout: float = 60.0,
    log: Path | None = None,
) -> subprocess.Popen:
    """Start franky-sim on ``host`` and return it once it says READY (``.host``, ``.scene_port``, ``.log``).

    ``cube``: its start position in the base frame [m] (None: an empty scene); ``scene_port``: serve
    the cube's pose and placement there; ``log``: where its output goes (default: a temporary file).
    """
    if not PYTHON.exists():
        raise RuntimeError(f"franky-sim's environment is missing ({PYTHON}); run `make setup` (scripts/setup.sh)")
    command = [str(PYTHON), str(SERVE), "--hostname", host]
    if cube is not None:
        command += ["--cube", str(cube[0]), str(cube[1])]
    if scene_port is not None:
        command += ["--scene-port", str(scene_port)]
    if log is None:
        log = Path(tempfile.mkstemp(prefix="franky_sim_", suffix=".log")[1])
    log.parent.mkdir(parents=True, exist_ok=True)
    with open(log, "w") as sink:
        proc = subprocess.Popen(command, stdout=sink, stderr=subprocess.STDOUT, text=True, start_new_session=True)
    try:
        deadline = time.monotonic() + timeout
        while "READY" not in log.read_text():
            if proc.poll() is not None:
                output = log.read_text()
                error = AddressTakenError if any(m in output for m in ADDRESS_TAKEN) else RuntimeError
                raise error("franky-sim exited:\n" + output)
            if time.monotonic() > deadline:
                raise RuntimeError(f"franky-sim did not start in {timeout:.0f} s:\n" + log.read_text())
            time.sleep(0.1)
    except BaseException:
        stop(proc)
        raise
    proc.host, proc.scene_port, proc.log = host, scene_port, log
    return proc


def stop(proc: subprocess.Popen) -> None:
    """Kill the server (and anything it started) and wait for it."""
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGKILL)
    proc.wait(timeout=10)


@contextmanager
def running(
    host: str,
    cube: tuple[float, float] | None = (0.5, 0.0),
    scene_port: int | None = None,
    timeout: float = 60.0,
    log: Path | None = None,
) -> Iterator[subprocess.Popen]:
    """Yield a running franky-sim on ``host`` (see :func:`start`); kill it afterwards, whatever happens."""
    proc = start(host, cube, scene_port, timeout, log)
    try:
        yield proc
    finally:
        stop(proc)
