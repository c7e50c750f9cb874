"""Which checkpoints of a ``lerobot-train`` run to evaluate, and which result counts as the best."""

from __future__ import annotations

import re
from pathlib import Path

from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.evaluation.trials import EvalResult

_STEP_DIR = re.compile(r"^\d+$")


def list_checkpoints(train_dir: Path, every: int = 1) -> list[tuple[int, Path]]:
    """``(step, pretrained_model/)`` of every ``every``-th checkpoint of a lerobot-train run, last included."""
    if every < 1:
        raise ConfigError(f"--every must be >= 1, got {every}")
    folder = Path(train_dir) / "checkpoints"
    if not folder.is_dir():
        raise ConfigError(
            f"{train_dir} has no checkpoints/ folder; point --train_dir at a lerobot-train --output_dir "
            "(checkpoints are saved every --save_freq steps)"
        )
    found = sorted(
        (int(p.name), p / "pretrained_model")
        for p in folder.iterdir()
        if _STEP_DIR.match(p.name) and (p / "pretrained_model" / "config.json").exists()
    )
    if not found:
        raise ConfigError(f"{folder} holds no finished checkpoint (no <step>/pretrained_model/config.json)")
    chosen = found[every - 1 :: every]
    if found[-1] not in chosen:
        chosen.append(found[-1])
    return chosen


def best_result(results: list[EvalResult]) -> EvalResult:
    """The highest success rate (the paper reports the best checkpoint); ties go to the later checkpoint."""
    return max(results, key=lambda r: (r.success_rate, r.step or 0))
