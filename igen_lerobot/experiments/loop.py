"""The outer loop of Algorithm 1, one resumable step at a time.

Iteration ``i`` (folders under ``output_dir/iter_<i>``):

1. ``train``: ``lerobot-train`` on ``D_i`` (the base dataset for ``i = 0``);
2. ``interventions``: ``m`` human-gated interventions on that policy (``igen-collect``);
3. ``generated``: ``n`` IntervenGen interventions with that policy and those sources;
4. ``dataset``: ``D_{i+1} = D_i + generated`` (LeRobot's aggregate).

Each step writes its output atomically, so re-running the same command skips finished steps and
resumes an interrupted one.
"""

from __future__ import annotations

import dataclasses
import json
import logging
from pathlib import Path

from igen_lerobot.collection.collect import collect
from igen_lerobot.collection.config_collect import CollectConfig
from igen_lerobot.core.env_config import task_config_class
from igen_lerobot.datasets.config_dataset import DatasetOutputConfig
from igen_lerobot.datasets.merge import merge_datasets
from igen_lerobot.datasets.reader import dataset_spec
from igen_lerobot.experiments.config_loop import LoopConfig
from igen_lerobot.generation.config_generate import GenerateConfig, SourceDatasetConfig
from igen_lerobot.generation.generate import generate
from igen_lerobot.training.lerobot_train import lerobot_train
from igen_lerobot.training.normaliser import observation_stats_args
from igen_lerobot.training.policy_source import PolicySourceConfig

logger = logging.getLogger(__name__)


def _complete(root: Path) -> bool:
    return (root / "meta" / "igen.json").exists()


def _train(cfg: LoopConfig, dataset: Path, output_dir: Path) -> Path:
    """``lerobot-train`` on ``dataset``, its inputs normalised as ``cfg.observation_stats`` says."""
    normaliser = observation_stats_args(cfg.observation_stats, Path(cfg.base_dataset), dataset)
    train = dataclasses.replace(cfg.train, extra_args=[*cfg.train.extra_args, *normaliser])
    return lerobot_train(train, dataset, f"local/{dataset.name}", output_dir)


def run_loop(cfg: LoopConfig) -> dict:
    """Run (or resume) ``cfg.iterations`` iterations; returns the paths it produced."""
    out = Path(cfg.output_dir)
    dataset = Path(cfg.base_dataset)
    produced: dict = {"iterations": []}
    for i in range(cfg.iterations):
        step_dir = out / f"iter_{i}"
        checkpoint = _train(cfg, dataset, step_dir / "train")
        policy = PolicySourceConfig(path=str(checkpoint), device=cfg.train.device)
        interventions = step_dir / "interventions"
        if not _complete(interventions):
            collect(
                CollectConfig(
                    env=task_config_class(cfg.task)(),
                    mode="interventions",
                    num_episodes=cfg.interventions,
                    seed=cfg.seed * 1000 + i,
                    operator=cfg.operator,
                    policy=policy,
                    dataset=DatasetOutputConfig(repo_id=f"local/iter{i}_interventions", root=str(interventions)),
                )
            )
        generated = step_dir / "generated"
        if not _complete(generated):
            generate(
                GenerateConfig(
                    mode="igen",
                    task=cfg.task,
                    source=SourceDatasetConfig(root=str(interventions)),
                    num_episodes=cfg.generated,
                    seed=cfg.seed * 1000 + i,
                    workers=cfg.workers,
                    policy=policy,
                    igen=dataclasses.replace(cfg.igen),
                    dataset=DatasetOutputConfig(repo_id=f"local/iter{i}_generated", root=str(generated)),
                )
            )
        merged = step_dir / "dataset"
        if not _complete(merged):
            spec = dataset_spec(dataset, "--base_dataset")
            merge_datasets([dataset, generated], merged, f"local/iter{i}_dataset", spec)
        produced["iterations"].append(
            {
                "policy": str(checkpoint),
                "interventions": str(interventions),
                "generated": str(generated),
                "dataset": str(merged),
            }
        )
        dataset = merged
    produced["dataset"] = str(dataset)
    if cfg.train_final:
        produced["policy"] = str(_train(cfg, dataset, out / "final_train"))
    return produced


def loop_command(cfg: LoopConfig) -> dict:
    """``igen-loop``: run the iterations and print what they produced."""
    produced = run_loop(cfg)
    print(json.dumps(produced, indent=2))
    cfg.dataset.publish(Path(produced["dataset"]))
    return produced
