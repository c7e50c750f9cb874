"""One core per worker process: BLAS, OpenMP and torch would otherwise each start a thread per core."""

from __future__ import annotations

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
