"""What a position-only policy is told of its hand's orientation: the goal, or the arm's measured one.

A policy trained on one arm without randomisation learnt to read that arm's slight tilt while it
moves, which no other arm reproduces; it is told the goal orientation its controller holds. A
policy trained on data generated with ``--env.randomize.hand_tilt_deg`` saw measured orientations
tilted by up to that angle and reads them as they are: told the goal instead, one such Block Grasp
checkpoint won 10 of 20 rehearsal trials on the training simulator, and 18 of 20 told the measured
one (docs/benchmarks.md). ``--hand_orientation=auto`` decides from the policy's training data, as
the checkpoint's ``train_config.json`` names it, and says why.
"""

from __future__ import annotations

import json
import logging
from pathlib import Path

logger = logging.getLogger(__name__)


def _origins(meta: dict) -> list[dict]:
    """The dataset's own origin and those of the parts a merged dataset was made of."""
    return [meta.get("origin") or {}, *[part.get("origin") or {} for part in meta.get("parts", [])]]


def training_hand_tilt(policy_path: str | Path) -> tuple[float | None, str]:
    """The largest randomised hand tilt [deg] in the policy's training data (0: none), and where it was read.

    None when the data cannot be read (a checkpoint without ``train_config.json``, or its dataset
    not on this machine); the text then says what is missing.
    """
    config = Path(policy_path) / "train_config.json"
    if not config.exists():
        return None, f"{config} is missing"
    try:
        dataset = json.loads(config.read_text()).get("dataset") or {}
    except (json.JSONDecodeError, AttributeError):
        return None, f"{config} is not a lerobot-train config (no JSON object)"
    root = dataset.get("root")
    meta_path = Path(root) / "meta" / "igen.json" if root else None
    if meta_path is None or not meta_path.exists():
        return None, f"the training dataset {root or dataset.get('repo_id')!r} has no meta/igen.json on this machine"
    try:
        meta = json.loads(meta_path.read_text())
    except json.JSONDecodeError:
        return None, f"{meta_path} is not valid JSON"
    tilts = [float((origin.get("randomization") or {}).get("hand_tilt_deg") or 0.0) for origin in _origins(meta)]
    return max(tilts), str(meta_path)


def resolve_hand_orientation(choice: str, policy_path: str | None) -> tuple[str, str]:
    """``(goal|measured, why)`` for ``--hand_orientation=choice``; ``auto`` reads the training data."""
    if choice != "auto":
        return choice, f"--hand_orientation={choice}"
    if policy_path is None:
        return "goal", "auto: the scripted policy reads no orientation"
    tilt, source = training_hand_tilt(policy_path)
    if tilt is None:
        why = (
            f"auto: {source}, so the policy is told the goal orientation; if it was trained on "
            "--env.randomize.hand_tilt_deg data, pass --hand_orientation=measured"
        )
        logger.warning(why)
        return "goal", why
    if tilt > 0:
        return "measured", f"auto: trained with hand tilts up to {tilt:g} deg ({source})"
    return "goal", f"auto: trained without hand tilt randomisation ({source})"
