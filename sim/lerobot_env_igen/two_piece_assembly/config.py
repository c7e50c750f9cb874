"""LeRobot env config for 2-Piece Assembly (``--env.type=two_piece_assembly``)."""

from __future__ import annotations

from dataclasses import dataclass, field

from lerobot.envs.configs import EnvConfig

from igen_lerobot.core.belief import Reveal
from igen_lerobot.core.error_models import ErrorModel
from igen_lerobot.core.paper import PaperTable, main_table
from igen_lerobot.core.task import TaskEnv
from lerobot_env_igen.config_in_hand_insertion import InHandInsertionEnvConfig
from lerobot_env_igen.placement import UniformRegion
from lerobot_env_igen.two_piece_assembly.spec import GEOMETRY, SPEC, paper_corruption


@EnvConfig.register_subclass("two_piece_assembly")
@dataclass
class TwoPieceAssemblyEnvConfig(InHandInsertionEnvConfig):
    """2-Piece Assembly with the paper's receptacle position error (+-4 cm per axis, at least 1 cm in one).

    Examples: ``lerobot-eval --env.type=two_piece_assembly --policy.path=.../pretrained_model``;
    the partial-observability variant: ``--env.reveal=direction``; the data-scaling table:
    ``igen-table --task=two_piece_assembly --table=scaling``.
    """

    base_spec = SPEC
    geometry = GEOMETRY
    paper_tables = (
        main_table(base=6, source_int=6, weighted_src_int=16, source_demo=12, mg_demo=16, igen_no_policy=52, igen=70),
        PaperTable(
            reveal=Reveal.DIRECTION,
            rows=("base", "source_int", "mg_demo", "igen_no_policy", "igen"),
            success={"base": 6, "source_int": 6, "mg_demo": 22, "igen_no_policy": 42, "igen": 66},
            caption="partial observability: the unit vector towards the true receptacle position at first contact",
        ),
        PaperTable(
            name="scaling",
            reveal=Reveal.FULL,
            rows=("source_int_100", "igen_200", "igen_1000", "igen_5000"),
            success={"source_int_100": 46, "igen_200": 34, "igen_1000": 70, "igen_5000": 88},
            caption="data scaling: I-Gen with 200 / 1000 / 5000 generated interventions from the same 10 sources, "
            "against 100 operator interventions",
        ),
    )

    task: str | None = "TwoPieceAssembly-v0"
    corruption: ErrorModel = field(default_factory=paper_corruption)
    receptacle_region: tuple[float, float] = (0.10, 0.10)  # [m] x, y extents of the receptacle's region

    def region(self) -> UniformRegion:
        return UniformRegion(self.receptacle_region, flag="env.receptacle_region")

    def make_task_env(self) -> TaskEnv:
        from lerobot_env_igen.two_piece_assembly.env import TwoPieceAssemblyEnv

        return TwoPieceAssemblyEnv(self)
