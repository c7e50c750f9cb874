"""LeRobot env config for Coffee (``--env.type=coffee``)."""

from __future__ import annotations

from dataclasses import dataclass, field

from lerobot.envs.configs import EnvConfig

from igen_lerobot.core.error_models import ErrorModel
from igen_lerobot.core.paper import main_table
from igen_lerobot.core.task import TaskEnv
from lerobot_env_igen.coffee.spec import GEOMETRY, SPEC, paper_corruption
from lerobot_env_igen.config_in_hand_insertion import InHandInsertionEnvConfig
from lerobot_env_igen.placement import UniformRegion


@EnvConfig.register_subclass("coffee")
@dataclass
class CoffeeEnvConfig(InHandInsertionEnvConfig):
    """Coffee with the paper's machine position error (2-4 cm in a uniform direction in the table plane).

    Example: ``lerobot-eval --env.type=coffee --policy.path=.../pretrained_model``. The paper has
    no partial-observability variant for Coffee: contact reveals the true pose (``--env.reveal=full``).
    """

    base_spec = SPEC
    geometry = GEOMETRY
    paper_tables = (
        main_table(base=2, source_int=10, weighted_src_int=6, source_demo=12, mg_demo=18, igen_no_policy=42, igen=80),
    )

    task: str | None = "Coffee-v0"
    corruption: ErrorModel = field(default_factory=paper_corruption)
    machine_region: tuple[float, float] = (0.10, 0.10)  # [m] x, y extents of the machine's region

    def region(self) -> UniformRegion:
        return UniformRegion(self.machine_region, flag="env.machine_region")

    def make_task_env(self) -> TaskEnv:
        from lerobot_env_igen.coffee.env import CoffeeEnv

        return CoffeeEnv(self)
