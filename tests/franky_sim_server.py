"""Start and stop franky-sim (a libfranka-protocol FR3 simulator) for the franky backend's tests.

franky-sim needs mujoco 4, so it lives in its own environment (tools/franky_sim/.venv, made by
scripts/setup.sh); the server runs there as a subprocess on a loopback address of its own, so
that parallel test runs do not share a robot.
"""

from __future__ import annotations

import os
import signal
import subprocess
import time
from contextlib import contextmanager
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PYTHON = ROOT / "tools" / "franky_sim" / ".venv" / "bin" / "python"
SERVE = ROOT / "tools" / "franky_sim" / "serve.py"


def free_loopback() -> str:
    """A loopback address unlikely to be used by another run (libfranka's ports are fixed)."""
    return f"127.0.{os.getpid() % 200 + 20}.{int(time.time() * 1000) % 200 + 20}"


@contextmanager
def franky_sim(cube: tuple[float, float] | None = (0.5, 0.0), timeout: float = 60.0, scene_port: int | None = None):
    """Yield the running franky-sim server (``.host``; ``.scene_port`` when asked for); kill it afterwards."""
    if not PYTHON.exists():
        raise RuntimeError(f"franky-sim's environment is missing ({PYTHON}); run `make setup` (scripts/setup.sh)")
    host = free_loopback()
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
            raise RuntimeError("franky-sim exited:\n" + "".join(lines))
        proc.host = host
        proc.scene_port = scene_port
        yield proc
    finally:
        stop(proc)


def stop(proc: subprocess.Popen) -> None:
    """Kill the server (and anything it started) and wait for it."""
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGKILL)
    proc.wait(timeout=10)
