"""Table-top Panda scenes composed from robosuite's models and compiled once to a MuJoCo model.

robosuite supplies the assets (Panda arm, Panda gripper, mount, table arena, box objects); we
compose them the way its manipulation environments do, but step the compiled model ourselves
(see :mod:`lerobot_env_igen.panda`), which keeps control cheap enough for data generation.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import mujoco
import numpy as np

from lerobot_env_igen.panda_spec import TABLE_TOP_Z

logger = logging.getLogger(__name__)

TABLE_FULL_SIZE = (0.8, 0.8, 0.05)  # [m] (the top at TABLE_TOP_Z)
CUBE_RGBA = (1.0, 0.0, 0.0, 1.0)


@dataclass(frozen=True)
class SceneNames:
    """MuJoCo names of the parts the controller and the task need."""

    arm_joints: tuple[str, ...] = tuple(f"robot0_joint{i}" for i in range(1, 8))
    finger_joints: tuple[str, ...] = ("gripper0_right_finger_joint1", "gripper0_right_finger_joint2")
    arm_actuators: tuple[str, ...] = tuple(f"robot0_torq_j{i}" for i in range(1, 8))
    finger_actuators: tuple[str, ...] = (
        "gripper0_right_gripper_finger_joint1",
        "gripper0_right_gripper_finger_joint2",
    )
    eef_site: str = "gripper0_right_grip_site"
    left_pad: str = "gripper0_right_finger1_pad_collision"
    right_pad: str = "gripper0_right_finger2_pad_collision"
    gripper_body_root: str = "gripper0_right_right_gripper"


def build_panda_table_scene(objects: list) -> tuple[mujoco.MjModel, np.ndarray]:
    """Compile a Panda + table scene holding robosuite objects.

    Args:
        objects: robosuite ``MujocoObject`` instances, free (default joints) or fixed
            (``joints=None``); each becomes a root body (``<name>_main``, or ``<name>_root`` for a
            composite object such as a ``Bin``) that the task moves at reset.

    Returns:
        The compiled model and robosuite's default Panda joint configuration (7,).
    """
    # robosuite is imported here so that registering the LeRobot plugin stays cheap.
    from robosuite.models.arenas import TableArena
    from robosuite.models.bases import robot_base_factory
    from robosuite.models.grippers import gripper_factory
    from robosuite.models.robots import Panda
    from robosuite.models.tasks import ManipulationTask

    robot = Panda(idn=0)
    robot.add_base(base=robot_base_factory(robot.default_base, idn=0))
    robot.add_gripper(gripper_factory(robot.default_gripper["right"], idn="0_right"))
    robot.set_base_xpos(robot.base_xpos_offset["table"](TABLE_FULL_SIZE[0]))
    arena = TableArena(table_full_size=TABLE_FULL_SIZE, table_offset=(0.0, 0.0, TABLE_TOP_Z))
    arena.set_origin([0, 0, 0])
    task = ManipulationTask(mujoco_arena=arena, mujoco_robots=[robot], mujoco_objects=list(objects))
    model = task.get_model(mode="mujoco")
    return model, np.asarray(robot.init_qpos, dtype=float)


def box(name: str, half_size: float | tuple[float, float, float], rgba: tuple[float, ...], fixed: bool = False):
    """A robosuite box object; ``fixed`` makes it part of the scenery (moved only at reset)."""
    from robosuite.models.objects import BoxObject

    half = [half_size] * 3 if np.isscalar(half_size) else list(half_size)
    return BoxObject(name=name, size=half, rgba=list(rgba), joints=None if fixed else "default")
