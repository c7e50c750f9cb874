"""Config of ``igen-eval`` (draccus, LeRobot style)."""

from __future__ import annotations

from dataclasses import dataclass, field

from lerobot.envs.configs import EnvConfig

from igen_lerobot.core.env_config import resolve_task_env
from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.training.policy_source import PolicySourceConfig
from igen_lerobot.viz.rerun_log import RerunConfig

EVAL_SEED = 1_000_003  # far from the seeds collection and generation use by default


@dataclass
class EvalConfig:
    """Success rate over seeded trials under the task's pose error and reveal-on-contact."""

    task: str | None = None  # shortcut for --env.type with the task's defaults (the paper's corruption)
    env: EnvConfig | None = None
    policy: PolicySourceConfig = field(default_factory=PolicySourceConfig)  # one checkpoint (or scripted)
    train_dir: str | None = None  # a lerobot-train --output_dir: evaluate its checkpoints, report the best
    every: int = 1  # with --train_dir: every k-th saved checkpoint (the last one always)
    n_trials: int = 50
    seed: int = EVAL_SEED
    output: str | None = None  # JSON file for the results
    rerun: RerunConfig = field(default_factory=RerunConfig)  # --rerun.mode=save --rerun.path=x.rrd: log each trial
    # processes running the trials, one simulation each: the same outcomes for any count, faster up to
    # one per core
    workers: int = 1
    # trials one process steps together, one batched policy call per control step for all of them (a
    # state-only BC-RNN checkpoint; other policies run one trial at a time): the same outcomes for any
    # count, about half the cost of a BC-RNN evaluation (docs/benchmarks.md)
    trials_together: int = 10

    def __post_init__(self) -> None:
        self.env = resolve_task_env(self.task, self.env)
        if self.policy.path and self.train_dir:
            raise ConfigError("give --policy.path (one checkpoint) or --train_dir (all of a run's), not both")
        if self.n_trials < 1:
            raise ConfigError(f"--n_trials must be >= 1, got {self.n_trials}")
        if self.every < 1:
            raise ConfigError(f"--every must be >= 1, got {self.every}")
        if self.workers < 1:
            raise ConfigError(f"--workers must be >= 1, got {self.workers}")
        if self.trials_together < 1:
            raise ConfigError(f"--trials_together must be >= 1 (1: one trial at a time), got {self.trials_together}")
        if self.workers > 1 and self.rerun.enabled:
            raise ConfigError("--rerun logs every trial's frames from one process; drop --rerun or pass --workers=1")
