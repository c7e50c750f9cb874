"""LeRobot env config for Nut Insertion (``--env.type=nut_insertion``)."""

from __future__ import annotations

from dataclasses import dataclass, field

from lerobot.envs.configs import EnvConfig

from igen_lerobot.core.belief import Reveal
from igen_lerobot.core.error_models import ErrorModel
from igen_lerobot.core.paper import PaperTable, main_table
from igen_lerobot.core.task import TaskEnv
from lerobot_env_igen.config_in_hand_insertion import InHandInsertionEnvConfig
from lerobot_env_igen.nut_insertion.spec import GEOMETRY, SPEC, paper_corruption
from lerobot_env_igen.placement import UniformRegion


@EnvConfig.register_subclass("nut_insertion")
@dataclass
class NutInsertionEnvConfig(InHandInsertionEnvConfig):
    """Nut Insertion with the paper's peg position error (+-4 cm per axis, at least 2 cm in one).

    Examples: ``lerobot-eval --env.type=nut_insertion --policy.path=.../pretrained_model``;
    the partial-observability variant: ``--env.reveal=contact_position``.
    """

    base_spec = SPEC
    geometry = GEOMETRY
    paper_tables = (
        main_table(base=22, source_int=40, weighted_src_int=50, source_demo=42, mg_demo=64, igen_no_policy=86, igen=98),
        PaperTable(
            reveal=Reveal.CONTACT_POSITION,
            rows=("base", "source_int", "mg_demo", "igen_no_policy", "igen"),
            success={"base": 26, "source_int": 40, "mg_demo": 46, "igen_no_policy": 68, "igen": 90},
            caption="partial observability: the mean position of the first nut-peg contact",
        ),
    )

    task: str | None = "NutInsertion-v0"
    corruption: ErrorModel = field(default_factory=paper_corruption)
    peg_region: tuple[float, float] = (0.10, 0.10)  # [m] x, y extents of the peg's region

    def region(self) -> UniformRegion:
        return UniformRegion(self.peg_region, flag="env.peg_region")

    def make_task_env(self) -> TaskEnv:
        from lerobot_env_igen.nut_insertion.env import NutInsertionEnv

        return NutInsertionEnv(self)
