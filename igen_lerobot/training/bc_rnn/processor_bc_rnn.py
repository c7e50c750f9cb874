"""BC-RNN's pre/post-processors: LeRobot's default normalisation pipeline."""

from __future__ import annotations

from typing import Any

import torch
from lerobot.processor import PolicyAction, PolicyProcessorPipeline, make_default_pre_post_processors

from igen_lerobot.training.bc_rnn.configuration_bc_rnn import BCRNNConfig


def make_bc_rnn_pre_post_processors(
    config: BCRNNConfig, dataset_stats: dict[str, dict[str, torch.Tensor]] | None = None
) -> tuple[
    PolicyProcessorPipeline[dict[str, Any], dict[str, Any]], PolicyProcessorPipeline[PolicyAction, PolicyAction]
]:
    """Normalise inputs (mean/std) and actions (min/max to [-1, 1]); unnormalise outputs."""
    return make_default_pre_post_processors(config, dataset_stats, normalizer_device=config.device)
