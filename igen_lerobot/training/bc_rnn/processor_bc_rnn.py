"""BC-RNN's pre/post-processors: LeRobot's default normalisation pipeline."""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Any

import torch
from lerobot.configs.types import NormalizationMode
from lerobot.processor import PolicyAction, PolicyProcessorPipeline, make_default_pre_post_processors

from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.training.bc_rnn.configuration_bc_rnn import BCRNNConfig

logger = logging.getLogger(__name__)

CONSTANT_STD = 1e-6  # [input units] a std or a range below this: the input is constant in the data


def constant_inputs(stats: dict[str, torch.Tensor]) -> torch.Tensor:
    """Which entries of one feature never vary in the data: a tiny std, or a tiny range where min/max are known.

    The range is the test that holds: LeRobot's per-episode std is sqrt(E[x^2] - E[x]^2) in float32
    (``RunningQuantileStats``), which cancels badly for a constant away from zero. 2-Piece Assembly's
    receptacle height, 0.82 in every frame (min = max), got a std of 3.3e-4, so a 1 cm observation
    error on it reached the network as 30 standard deviations; Nut Insertion's peg height, 0.865 in
    every frame, got 5.7e-8.
    """
    std = torch.as_tensor(stats["std"])
    constant = std < CONSTANT_STD
    if "min" in stats and "max" in stats:
        spread = torch.as_tensor(stats["max"]) - torch.as_tensor(stats["min"])
        constant = constant | (spread.reshape(std.shape) < CONSTANT_STD)
    return constant


def make_bc_rnn_pre_post_processors(
    config: BCRNNConfig, dataset_stats: dict[str, dict[str, torch.Tensor]] | None = None
) -> tuple[
    PolicyProcessorPipeline[dict[str, Any], dict[str, Any]], PolicyProcessorPipeline[PolicyAction, PolicyAction]
]:
    """Normalise inputs (mean/std) and actions (min/max to [-1, 1]); unnormalise outputs.

    The stats saved with a checkpoint are the ones used here, adjustments included, so evaluation
    normalises as training did.
    """
    return make_default_pre_post_processors(config, input_stats(config, dataset_stats), normalizer_device=config.device)


def input_stats(
    config: BCRNNConfig, stats: dict[str, dict[str, torch.Tensor]] | None
) -> dict[str, dict[str, torch.Tensor]] | None:
    """``stats`` as BC-RNN normalises with them (another dataset's, the constant-input std, the tolerance).

    With ``config.observation_stats`` the mean/std-normalised inputs take that dataset's statistics.
    A mean/std-normalised input that never varies in the data gets ``config.constant_input_std``;
    then every such input's std gets ``config.obs_std_tolerance`` added.
    """
    if stats is None:
        return stats
    normalised = {
        key
        for key, feature in config.input_features.items()
        if config.normalization_mapping.get(feature.type.value) is NormalizationMode.MEAN_STD
    }
    if config.observation_stats is not None:
        stats = {**stats, **observation_stats_of(Path(config.observation_stats), normalised & set(stats))}
    if config.obs_std_tolerance == 0 and config.constant_input_std == 0:
        warn_constant_inputs(stats, normalised)
        return stats
    out = dict(stats)
    for key in normalised & set(stats):
        std = torch.as_tensor(stats[key]["std"])
        if config.constant_input_std > 0:  # constant inputs: only centred, their deviations kept in input units
            std = torch.where(constant_inputs(stats[key]), torch.full_like(std, config.constant_input_std), std)
        out[key] = {**stats[key], "std": std + config.obs_std_tolerance}
    return out


def observation_stats_of(root: Path, keys: set[str]) -> dict[str, dict[str, torch.Tensor]]:
    """The statistics of ``keys`` recorded in the dataset at ``root`` (``policy.observation_stats``)."""
    from lerobot.datasets.io_utils import load_stats

    stats = load_stats(root) if root.is_dir() else None
    if stats is None:
        raise ConfigError(
            f"policy.observation_stats={root} holds no meta/stats.json; give the root of a LeRobot dataset "
            "of the same task (igen-table passes its base dataset D)"
        )
    missing = sorted(key for key in keys if key not in stats or "std" not in stats[key])
    if missing:
        raise ConfigError(
            f"policy.observation_stats={root} has no mean/std for {missing}; give a dataset with the same "
            "observation features as the training data"
        )
    return {key: {name: torch.as_tensor(value) for name, value in stats[key].items()} for key in keys}


def warn_constant_inputs(stats: dict[str, dict[str, torch.Tensor]], keys: set[str]) -> list[str]:
    """Name the inputs that never vary in the data; mean/std would blow up any deviation from them.

    A fixed object's height or orientation is constant in demonstrations, its std ~1e-8; an
    observation error of 1 mm on it then reaches the network as ~1e5 standard deviations.
    """
    found = []
    for key in sorted(keys & set(stats)):
        constant = [i for i, c in enumerate(constant_inputs(stats[key]).flatten().tolist()) if c]
        if constant:
            found.append(f"{key}{constant}")
    if found:
        logger.warning(
            "inputs that never vary in the training data (std or range < %g): %s. Mean/std normalisation divides any "
            "deviation from them at run time by that std (LeRobot adds only 1e-8); --policy.obs_std_tolerance=1e-3 "
            "(robomimic's value) bounds it",
            CONSTANT_STD,
            ", ".join(found),
        )
    return found
