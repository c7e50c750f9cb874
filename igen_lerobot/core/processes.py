"""Worker processes: one compute thread each, their CPU time counted where the parent's is, their priority."""

from __future__ import annotations

import contextlib
import logging
import multiprocessing.forkserver
import os
from collections.abc import Iterator

logger = logging.getLogger(__name__)


def limit_threads() -> None:
    """Pin this process to one compute thread; call it first thing in a worker, before any model runs.

    A 2-thread torch pool beside another busy process spins while it waits for its second thread:
    one evaluation worker ran 6 trials in 2 s at one thread and 14-33 s at two beside a table's step.
    """
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ[var] = "1"
    try:
        import torch

        torch.set_num_threads(1)
    except ImportError:  # pragma: no cover - torch ships with lerobot
        pass


def reap_forkserver() -> None:
    """Stop this process's multiprocessing fork server, if one runs, and wait for it to exit.

    Workers forked from the server are its children, not ours: their CPU time reaches our
    ``RUSAGE_CHILDREN`` (what a table step records as its cost) only once the server, which waited
    for them, is waited for in turn. Left running, it would exit unreaped with the process and take
    the workers' CPU time with it. Call it once the pool's workers have exited; the next pool starts
    a new server.
    """
    server = multiprocessing.forkserver._forkserver
    stop = getattr(server, "_stop", None)  # CPython's own (closes the server's pipe, then waits for it)
    if stop is None or getattr(server, "_forkserver_pid", None) is None:
        return
    with contextlib.suppress(OSError, ChildProcessError):
        stop()


@contextlib.contextmanager
def normal_priority() -> Iterator[bool]:
    """Run the block, and the processes it starts, at nice 0 when this process runs niced; yields whether it does.

    A run paced on a clock (franky-sim's 1 kHz loop, the 20 Hz deployment loop) inside a long job
    started at low priority (the table lanes run at nice 10) would otherwise share the cores as an equal
    with whatever else runs niced. Not enough on its own: beside two niced trainings, franky at nice 0
    still lost every trial to the watchdog (docs/benchmarks.md), so the lanes also pause each other
    while franky runs. Raising a priority needs CAP_SYS_NICE: without it the block runs at the inherited
    niceness, and says so in the log.
    """
    before = os.getpriority(os.PRIO_PROCESS, 0)
    raised = False
    if before > 0:
        try:
            os.setpriority(os.PRIO_PROCESS, 0, 0)
            raised = True
        except PermissionError:
            logger.warning(
                "cannot raise this process from nice %d to 0 (needs CAP_SYS_NICE); runs at %d", before, before
            )
    try:
        yield raised or before <= 0
    finally:
        if raised:
            os.setpriority(os.PRIO_PROCESS, 0, before)
