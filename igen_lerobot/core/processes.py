"""Worker processes: one compute thread each, and their CPU time counted where the parent's is."""

from __future__ import annotations

import contextlib
import multiprocessing.forkserver
import os


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
