"""What to pass to ``lerobot-train`` (``--train.*`` in igen-loop and igen-table)."""

from __future__ import annotations

from dataclasses import dataclass, field

from igen_lerobot.core.exceptions import ConfigError


@dataclass
class TrainConfig:
    """What to pass to ``lerobot-train``."""

    policy_type: str = "bc_rnn"
    steps: int = 2000
    batch_size: int = 100
    num_workers: int = 2
    device: str = "cpu"
    seed: int = 1000
    save_freq: int = 0  # checkpoint every this many steps (0: only at the end); igen-eval picks the best
    # torch's threads in lerobot-train (OMP_NUM_THREADS). The weights differ between thread counts, and
    # torch's default is one per core, so a run that must reproduce elsewhere fixes it; None: the default
    threads: int | None = None
    extra_args: list[str] = field(default_factory=list)  # passed verbatim, e.g. ["--policy.horizon=10"]

    def __post_init__(self) -> None:
        if self.steps < 1:
            raise ConfigError(f"train.steps must be >= 1, got {self.steps}")
        if self.batch_size < 1:
            raise ConfigError(f"train.batch_size must be >= 1, got {self.batch_size}")
        if self.save_freq < 0:
            raise ConfigError(f"train.save_freq must be >= 0 (0: only the last step), got {self.save_freq}")
        if self.threads is not None and self.threads < 1:
            raise ConfigError(f"train.threads must be >= 1 (or unset for torch's default), got {self.threads}")
