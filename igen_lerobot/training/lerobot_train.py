"""Train a policy with LeRobot's own ``lerobot-train`` (as a subprocess, exactly as a user would)."""

from __future__ import annotations

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


def clear_interrupted_run(output_dir: Path) -> None:
    """Remove a run that stopped before its last checkpoint: lerobot-train refuses an existing output_dir."""
    output_dir = Path(output_dir)
    if output_dir.exists() and not (checkpoint_path(output_dir) / "config.json").exists():
        import shutil

        logger.info("removing the interrupted training run %s", output_dir)
        shutil.rmtree(output_dir)


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


def lerobot_train(cfg: TrainConfig, dataset_root: Path, repo_id: str, output_dir: Path) -> Path:
    """Run ``lerobot-train`` on a local dataset; returns the last checkpoint's ``pretrained_model/``."""
    output_dir = Path(output_dir)
    done = checkpoint_path(output_dir)
    if (done / "config.json").exists():
        logger.info("training already done: %s", done)
        return done
    clear_interrupted_run(output_dir)
    command = train_command(cfg, dataset_root, repo_id, output_dir)
    logger.info("training: %s", " ".join(command))
    log = output_dir.with_name(output_dir.name + ".log")
    log.parent.mkdir(parents=True, exist_ok=True)
    with open(log, "w") as out:
        result = subprocess.run(command, stdout=out, stderr=subprocess.STDOUT, env={**os.environ}, check=False)
    if result.returncode != 0:
        tail = log.read_text()[-2000:]
        raise TrainingFailedError(f"lerobot-train failed (exit {result.returncode}); log {log}:\n{tail}")
    if not (done / "config.json").exists():
        raise TrainingFailedError(f"lerobot-train finished without a checkpoint at {done}; log {log}")
    return done
