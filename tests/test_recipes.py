"""Every shipped recipe is a valid config for the command its file name names."""

from pathlib import Path

import draccus
import pytest

from igen_lerobot.collection.config_collect import CollectConfig
from igen_lerobot.core.env_config import known_tasks
from igen_lerobot.generation.config_generate import GenerateConfig

RECIPES = sorted((Path(__file__).parents[1] / "datasets" / "recipes").glob("*.yaml"))
CONFIGS = {"collect": CollectConfig, "generate": GenerateConfig}


def test_recipes_exist_for_every_command():
    assert {p.name.split("_")[0] for p in RECIPES} == set(CONFIGS)


@pytest.mark.parametrize("recipe", RECIPES, ids=lambda p: p.stem)
def test_recipe_parses(recipe):
    known_tasks()
    cfg = draccus.parse(CONFIGS[recipe.name.split("_")[0]], config_path=recipe, args=[])
    assert cfg.env.type in known_tasks()
    assert cfg.dataset.root and cfg.dataset.repo_id
    assert cfg.dataset.root.startswith("outputs/")
