"""Train a policy with LeRobot's own ``lerobot-train`` (as a subprocess, exactly as a user would)."""

from __future__ import annotations

import json
import logging
import os
import subprocess
import sys
from pathlib import Path

from igen_lerobot.core.exceptions import IgenError
from igen_lerobot.training.config_train import TrainConfig

logger = logging.getLogger(__name__)


class TrainingFailedError(IgenError, RuntimeError):
    """lerobot-train exited with an error; the message carries the end of its log."""


def checkpoint_path(output_dir: Path) -> Path:
    """The ``pretrained_model/`` folder of the last checkpoint of a lerobot-train run."""
    return Path(output_dir) / "checkpoints" / "last" / "pretrained_model"


def step_checkpoint(output_dir: Path, steps: int, step: int) -> Path:
    """The ``pretrained_model/`` folder a run of ``steps`` steps saves at ``step`` (named as LeRobot names it)."""
    from lerobot.common.train_utils import get_step_checkpoint_dir

    return get_step_checkpoint_dir(Path(output_dir), steps, step) / "pretrained_model"


def final_checkpoint(output_dir: Path, steps: int) -> Path:
    """The ``pretrained_model/`` folder a run of ``steps`` steps leaves at its end."""
    return step_checkpoint(output_dir, steps, steps)


def last_saved_step(output_dir: Path) -> int | None:
    """The step of a run's last checkpoint (None: no checkpoint yet)."""
    state = Path(output_dir) / "checkpoints" / "last" / "training_state" / "training_step.json"
    if not (checkpoint_path(output_dir) / "config.json").exists() or not state.exists():
        return None
    return int(json.loads(state.read_text())["step"])


def is_finished(output_dir: Path, steps: int) -> bool:
    """Whether the run reached ``steps`` (a run stopped after an intermediate checkpoint has not)."""
    saved = last_saved_step(output_dir)
    return saved is not None and saved >= steps


def clear_interrupted_run(output_dir: Path) -> None:
    """Remove a run that stopped before its first checkpoint: lerobot-train refuses an existing output_dir."""
    output_dir = Path(output_dir)
    if output_dir.exists() and last_saved_step(output_dir) is None:
        import shutil

        logger.info("removing the interrupted training run %s (no checkpoint to resume from)", output_dir)
        shutil.rmtree(output_dir)


def train_env(cfg: TrainConfig) -> dict[str, str]:
    """Environment variables ``lerobot-train`` runs with: the thread count, when the config fixes it."""
    return {} if cfg.threads is None else {"OMP_NUM_THREADS": str(cfg.threads)}


def train_command(cfg: TrainConfig, dataset_root: Path, repo_id: str, output_dir: Path) -> list[str]:
    """The ``lerobot-train`` command line, as a user would type it."""
    return [
        str(Path(sys.executable).parent / "lerobot-train"),
        f"--policy.type={cfg.policy_type}",
        f"--policy.device={cfg.device}",
        "--policy.push_to_hub=false",
        f"--dataset.repo_id={repo_id}",
        f"--dataset.root={dataset_root}",
        f"--output_dir={output_dir}",
        f"--steps={cfg.steps}",
        f"--batch_size={cfg.batch_size}",
        f"--num_workers={cfg.num_workers}",
        f"--save_freq={cfg.save_freq or cfg.steps}",
        f"--seed={cfg.seed}",
        "--wandb.enable=false",
        *cfg.extra_args,
    ]


def resume_command(cfg: TrainConfig, output_dir: Path) -> list[str]:
    """LeRobot's own resume from the run's last checkpoint (optimizer, RNG and step restored)."""
    config = checkpoint_path(output_dir) / "train_config.json"
    return [
        str(Path(sys.executable).parent / "lerobot-train"),
        "--resume=true",
        f"--config_path={config}",
        f"--steps={cfg.steps}",
        f"--save_freq={cfg.save_freq or cfg.steps}",
    ]


def run_command(cfg: TrainConfig, dataset_root: Path, repo_id: str, output_dir: Path) -> list[str]:
    """The command that brings the run at ``output_dir`` to ``cfg.steps``: resumed if it has a checkpoint.

    Hours of CPU training are not thrown away when a session ends: a run with a checkpoint short of
    its steps continues from it; one without a checkpoint starts again.
    """
    clear_interrupted_run(output_dir)
    saved = last_saved_step(output_dir)
    if saved is None:
        return train_command(cfg, dataset_root, repo_id, output_dir)
    logger.info("resuming the training run %s from step %d of %d", output_dir, saved, cfg.steps)
    return resume_command(cfg, output_dir)


def lerobot_train(cfg: TrainConfig, dataset_root: Path, repo_id: str, output_dir: Path) -> Path:
    """Run ``lerobot-train`` on a local dataset; returns the last checkpoint's ``pretrained_model/``."""
    output_dir = Path(output_dir)
    done = checkpoint_path(output_dir)
    if is_finished(output_dir, cfg.steps):
        logger.info("training already done: %s", done)
        return done
    command = run_command(cfg, dataset_root, repo_id, output_dir)
    logger.info("training: %s", " ".join([*(f"{k}={v}" for k, v in train_env(cfg).items()), *command]))
    log = output_dir.with_name(output_dir.name + ".log")
    log.parent.mkdir(parents=True, exist_ok=True)
    with open(log, "a") as out:
        result = subprocess.run(
            command, stdout=out, stderr=subprocess.STDOUT, env={**os.environ, **train_env(cfg)}, check=False
        )
    if result.returncode != 0:
        tail = log.read_text()[-2000:]
        raise TrainingFailedError(f"lerobot-train failed (exit {result.returncode}); log {log}:\n{tail}")
    if not is_finished(output_dir, cfg.steps):
        raise TrainingFailedError(f"lerobot-train finished without a checkpoint at {done}; log {log}")
    return done
