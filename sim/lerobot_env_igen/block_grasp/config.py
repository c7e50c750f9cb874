"""LeRobot env config for Block Grasp (``--env.type=block_grasp``)."""

from __future__ import annotations

from dataclasses import dataclass, field

from lerobot.envs.configs import EnvConfig

from igen_lerobot.core.actions import ActionSpace, DeltaPositionActions
from igen_lerobot.core.agents import Operator, Policy
from igen_lerobot.core.belief import Reveal
from igen_lerobot.core.error_models import ErrorModel
from igen_lerobot.core.paper import VARIANTS, PaperTable
from igen_lerobot.core.task import TaskEnv
from lerobot_env_igen.block_grasp.spec import SPEC, paper_corruption
from lerobot_env_igen.config_panda_task import PandaTaskEnvConfig
from lerobot_env_igen.placement import UniformRegion


@EnvConfig.register_subclass("block_grasp")
@dataclass
class BlockGraspEnvConfig(PandaTaskEnvConfig):
    """Block Grasp with the paper's pose error (+-1 cm x, +-7 cm y, |y| >= 2.5 cm).

    Example: ``lerobot-eval --env.type=block_grasp --policy.path=outputs/train/.../pretrained_model``
    """

    base_spec = SPEC
    paper_tables = (
        PaperTable(
            reveal=Reveal.FULL,
            rows=VARIANTS,
            success={"base": 6, "source_int": 26, "mg_demo": 42, "igen_no_policy": 86, "igen": 100},
            caption="sim-to-real table, Block Grasp in simulation (50 trials) and on a real Franka (10 trials)",
            real={"base": 0, "source_int": 10, "mg_demo": 50, "igen_no_policy": 60, "igen": 90},
            real_trials=10,
        ),
    )

    task: str | None = "BlockGrasp-v0"
    corruption: ErrorModel = field(default_factory=paper_corruption)
    cube_region: tuple[float, float] = (0.20, 0.30)  # [m] x, y extents of the cube's start region

    def region(self) -> UniformRegion:
        return UniformRegion(self.cube_region, flag="env.cube_region")

    def make_action_space(self) -> ActionSpace:
        return DeltaPositionActions(max_delta=self.max_delta)

    def make_task_env(self) -> TaskEnv:
        from lerobot_env_igen.block_grasp.env import BlockGraspEnv

        return BlockGraspEnv(self)

    def make_scripted_operator(self) -> Operator:
        from lerobot_env_igen.block_grasp.scripted import ScriptedGraspOperator

        return ScriptedGraspOperator()

    def make_scripted_policy(self) -> Policy:
        from lerobot_env_igen.block_grasp.scripted import ScriptedGraspPolicy

        return ScriptedGraspPolicy()
