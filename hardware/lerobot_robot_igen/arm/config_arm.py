"""Which arm drives the loop (``--robot.type`` of igen-deploy, ``--robot.arm.type`` of the LeRobot robot).

Kept apart from the deployment config so that LeRobot, which imports this plugin on every
``lerobot-*`` command, loads nothing heavy: a backend's libraries load in ``make_driver``.
"""

from __future__ import annotations

import abc
from dataclasses import dataclass

import draccus

from lerobot_robot_igen.arm.driver import ArmDriver

# Where a real, table-mounted arm's base sits in the task frame: the table top is z = 0.8 m in
# training, and the cube region is centred 0.56 m in front of the base, as in the simulator.
REAL_WORLD_FROM_BASE_XYZ = (-0.56, 0.0, 0.8)


@dataclass
class ArmBackendConfig(draccus.ChoiceRegistry, abc.ABC):
    """Which arm the loop drives."""

    @property
    def simulated(self) -> bool:
        return False

    @abc.abstractmethod
    def make_driver(self, env_config=None) -> ArmDriver:
        """The (not yet connected) driver; a simulated arm builds ``env_config``'s task scene, a real one ignores it."""


@ArmBackendConfig.register_subclass("sim")
@dataclass
class SimArmBackendConfig(ArmBackendConfig):
    """The task's scene in MuJoCo (rehearsal; Block Grasp unless igen-deploy's --task says otherwise)."""

    fps: int = 20

    @property
    def simulated(self) -> bool:
        return True

    def make_driver(self, env_config=None) -> ArmDriver:
        from dataclasses import replace

        from lerobot_robot_igen.arm.mujoco_arm import MujocoArm, MujocoArmConfig

        if env_config is not None:
            env_config = replace(env_config, fps=self.fps)
        return MujocoArm(MujocoArmConfig(fps=self.fps), env_config)
