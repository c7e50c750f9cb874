"""Every shipped recipe is a valid config for the command it names."""

from pathlib import Path

import draccus
import pytest

from igen_lerobot.config_collect import CollectConfig
from igen_lerobot.corruption import BoxNoise
from igen_lerobot.env_config import known_tasks

RECIPES = sorted((Path(__file__).parents[1] / "datasets" / "recipes").glob("*.yaml"))


def test_recipes_exist():
    assert len(RECIPES) >= 2


@pytest.mark.parametrize("recipe", RECIPES, ids=lambda p: p.stem)
def test_recipe_parses(recipe):
    known_tasks()
    cfg = draccus.parse(CollectConfig, config_path=recipe, args=[])
    assert cfg.env.type in known_tasks()
    assert cfg.dataset.root and cfg.dataset.repo_id
    if cfg.mode == "interventions":
        assert isinstance(cfg.env.corruption, BoxNoise)
