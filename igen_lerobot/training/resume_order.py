"""A training resumed after its first epoch continues the data order it was stopped in.

LeRobot 0.6 restores ``EpisodeAwareSampler`` at the saved epoch and offset, then hands the loader to
accelerate, whose loader calls ``sampler.set_epoch(iteration)`` at the start of every pass, with
``iteration`` counted from 0 in each process. A run resumed in epoch ``e >= 1`` therefore replays
epoch 0's permutation from the saved offset, then epochs 1, 2, ...: different batches than the run
it resumes, so its weights differ from an uninterrupted run's (measured: a Nut Insertion base
policy resumed at step 2000 of 5000; upstream: huggingface/lerobot pull request 4692, open).

``install`` makes ``set_epoch`` count from the epoch ``load_state_dict`` restored, so accelerate's
pass ``k`` is epoch ``e + k``. A run never resumed restores nothing and is unchanged.
"""

from __future__ import annotations

import logging

logger = logging.getLogger(__name__)

# lerobot releases whose training loop has the reset above (checked by tests/test_training_resume.py)
AFFECTED = ("0.6.",)


def _set_epoch(self, epoch: int) -> None:
    self._epoch = getattr(self, "_igen_resumed_epoch", 0) + epoch


def install() -> bool:
    """Patch ``EpisodeAwareSampler`` where the installed lerobot has the reset; returns whether it did."""
    import lerobot
    from lerobot.datasets.sampler import EpisodeAwareSampler

    if not str(lerobot.__version__).startswith(AFFECTED):
        logger.warning("lerobot %s: resume order not patched (checked for %s)", lerobot.__version__, AFFECTED)
        return False
    if getattr(EpisodeAwareSampler, "_igen_resume_order", False):
        return True
    load_state_dict = EpisodeAwareSampler.load_state_dict

    def load_and_remember_epoch(self, state: dict) -> None:
        load_state_dict(self, state)
        self._igen_resumed_epoch = state["epoch"]

    EpisodeAwareSampler.load_state_dict = load_and_remember_epoch
    EpisodeAwareSampler.set_epoch = _set_epoch
    EpisodeAwareSampler._igen_resume_order = True
    return True
