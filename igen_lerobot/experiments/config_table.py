"""Config of ``igen-table``: the paper's dataset variants on one task, trained and evaluated alike."""

from __future__ import annotations

from dataclasses import dataclass, field

from igen_lerobot.core.env_config import task_config_class
from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.evaluation.config_eval import EVAL_SEED
from igen_lerobot.training.lerobot_train import TrainConfig

# The rows of the paper's Block Grasp table, in its order.
VARIANTS = ("base", "source_int", "weighted_src_int", "source_demo", "mg_demo", "igen_no_policy", "igen")


@dataclass
class TableConfig:
    """Sizes follow the paper (10 source episodes, 1000 generated, 50 trials); shrink them for a smoke run."""

    task: str = "block_grasp"
    variants: list[str] = field(default_factory=lambda: list(VARIANTS))
    source_episodes: int = 10  # human (here: scripted-operator) episodes of each kind
    base_demos: int = 1000  # MimicGen demonstrations forming the base dataset D
    generated: int = 1000  # synthetic episodes for MG Demo, I-Gen - Policy and I-Gen
    workers: int = 2
    seed: int = 0
    train: TrainConfig = field(default_factory=lambda: TrainConfig(steps=2000, save_freq=500))
    eval_every: int = 1  # evaluate every k-th saved checkpoint, report the best
    n_trials: int = 50
    eval_seed: int = EVAL_SEED
    output_dir: str = "outputs/table"
    results: str = "docs/results.md"  # the markdown table; the JSON goes next to it (.json)
    # run each command inside this process (same arguments, same code, recorded the same) instead of
    # a subprocess: saves the ~20 s of imports per command that dominate small smoke runs
    in_process: bool = False

    def __post_init__(self) -> None:
        task_config_class(self.task)
        unknown = [v for v in self.variants if v not in VARIANTS]
        if unknown or not self.variants:
            raise ConfigError(f"--variants must be a non-empty subset of {list(VARIANTS)}, got {self.variants}")
        for name in ("source_episodes", "base_demos", "generated", "workers", "n_trials", "eval_every"):
            if getattr(self, name) < 1:
                raise ConfigError(f"--{name} must be >= 1, got {getattr(self, name)}")
        if not self.results.endswith(".md"):
            raise ConfigError(f"--results must name a markdown file (.md), got {self.results!r}")
