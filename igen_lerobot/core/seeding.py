"""Per-episode seeds derived from one run seed, so any run is reproducible and resumable."""

from __future__ import annotations

import numpy as np


def episode_seed(run_seed: int, attempt: int) -> int:
    """Seed of attempt ``attempt`` of a run: independent streams, reproducible from the run seed."""
    return int(np.random.SeedSequence([run_seed, attempt]).generate_state(1)[0])
