"""The config every Panda table-top task's config extends (``--env.type=<task>``).

It holds what the Panda tasks share: the paper's 20 Hz, the episode length, the per-step clip on
the end-effector displacement, and the checks that refuse a bad action limit or start region by
its flag when the config is made (not later, when an env is built). A task adds its start region
as a field named for its object (``cube_region``, ``peg_region``) and returns it from
:meth:`PandaTaskEnvConfig.region`; the env (:class:`~lerobot_env_igen.panda_task.PandaTaskEnv`)
is built from the config.
"""

from __future__ import annotations

import abc
from dataclasses import dataclass, field

from igen_lerobot.core.actions import DeltaPositionActions
from igen_lerobot.core.env_config import TaskEnvConfig
from lerobot_env_igen.arm_randomization import ArmRandomization
from lerobot_env_igen.panda_spec import PANDA_EPISODE_STEPS, PANDA_FPS
from lerobot_env_igen.placement import UniformRegion


@dataclass
class PandaTaskEnvConfig(TaskEnvConfig, abc.ABC):
    """Base of the Panda tasks' configs (the task's own: ``base_spec``, its region, its env and agents)."""

    fps: int = PANDA_FPS
    episode_length: int = PANDA_EPISODE_STEPS
    max_delta: float = 0.03  # [m] per-step clip on the commanded end-effector displacement
    # what a deployed arm changes, drawn per episode from its seed (off by default): arm_randomization.py
    randomize: ArmRandomization = field(default_factory=ArmRandomization)

    def __post_init__(self) -> None:
        super().__post_init__()
        action_space = self.make_action_space()  # a bad --env.max_delta (or --env.max_rotation) fails here, by its flag
        self.region()  # and a bad start region
        self.randomize.check(1.0 / self.fps, holds_orientation=isinstance(action_space, DeltaPositionActions))

    def randomization(self) -> dict | None:
        return self.randomize.describe()

    @abc.abstractmethod
    def region(self) -> UniformRegion:
        """Where the task's placed object starts: its region field, with the flag it is refused by."""
