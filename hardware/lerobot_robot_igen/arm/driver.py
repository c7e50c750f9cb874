"""What the deployment loop needs from a robot arm, whatever drives it.

A backend (franky-control for a real FR3/Panda, MuJoCo for the Block Grasp scene) only moves the
arm: it reports its state and follows absolute Cartesian targets in the **robot base frame**.
Limits (workspace, speed, watchdog) are not a backend's business: :class:`~lerobot_robot_igen.arm.safe_arm.SafeArm`
enforces them in one place for every backend.

Units: metres, radians, seconds, newtons. Poses are 4x4 homogeneous matrices ``T_base_eef``; the
end-effector frame is the one the policy was trained with (robosuite's grip site: between the
finger pads, z along the approach direction).
"""

from __future__ import annotations

import abc
from dataclasses import dataclass

import numpy as np

from lerobot_robot_igen.errors import HardwareError

__all__ = ["ArmState", "ArmDriver", "DriverError", "ConnectionLostError", "MotionTimeoutError"]


class DriverError(HardwareError):
    """The arm refused or aborted a command (e.g. a reflex); :meth:`ArmDriver.recover` may clear it."""


class ConnectionLostError(DriverError):
    """The connection to the robot (or its simulator) is gone; the episode must end."""


class MotionTimeoutError(DriverError):
    """A blocking motion did not finish in its time; the arm was told to stop.

    Not retried: an arm (or simulator) that stopped answering would only time out again.
    """


@dataclass(frozen=True)
class ArmState:
    """One reading of the arm."""

    T_base_eef: np.ndarray  # (4, 4) end-effector pose in the robot base frame
    joint_positions: np.ndarray  # (7,) [rad]
    gripper_width: float  # distance between the fingers [m]
    external_force: float  # magnitude of the estimated external force at the end effector [N]
    timestamp: float  # time.monotonic() of the reading [s]

    @property
    def eef_position(self) -> np.ndarray:
        return self.T_base_eef[:3, 3]


class ArmDriver(abc.ABC):
    """A 7-DOF arm with a parallel gripper, commanded by absolute Cartesian targets.

    ``send_target`` must return at once (the arm keeps moving towards the last target), so that
    a 20 Hz loop can stream targets; ``set_gripper`` likewise. Every method may raise
    :class:`ConnectionLostError` once the robot is unreachable.
    """

    @abc.abstractmethod
    def connect(self) -> None:
        """Open the connection; afterwards :meth:`read_state` works."""

    @abc.abstractmethod
    def disconnect(self) -> None:
        """Stop any motion and close the connection; safe to call twice."""

    @property
    @abc.abstractmethod
    def is_connected(self) -> bool:
        """Whether :meth:`connect` succeeded and :meth:`disconnect` has not run since."""

    @abc.abstractmethod
    def read_state(self) -> ArmState:
        """The arm's current state."""

    @abc.abstractmethod
    def send_target(self, T_base_eef: np.ndarray) -> None:
        """Move towards ``T_base_eef`` (4x4) without waiting; replaces the previous target."""

    @abc.abstractmethod
    def set_gripper(self, closed: bool) -> None:
        """Close (grasp whatever is between the fingers) or open the gripper, without waiting."""

    @abc.abstractmethod
    def stop(self) -> None:
        """Halt the arm where it is, now. Must not raise for an arm that is already still."""

    @abc.abstractmethod
    def recover(self) -> None:
        """Clear a reflex/error state so that commands are accepted again."""

    def move_home(self) -> None:  # noqa: B027 - optional: not every backend has a home pose
        """Bring the arm to its start pose (blocking), gripper open."""

    def clock(self) -> float:
        """The arm's time [s]: what the watchdog measures staleness in (simulated arms: sim time)."""
        import time

        return time.monotonic()

    def robot_time(self) -> float | None:
        """The arm's own clock [s] where it reports one (libfranka's robot time), else None.

        On a real arm it runs with the wall clock; a simulator behind the arm's protocol may run
        slower (franky-sim's Python 1 kHz loop), and a loop paced on it still gives the arm its periods.
        """
        return None

    def sync(self, period: float) -> None:  # noqa: B027 - real arms move on their own
        """Let one control period pass. Real arms move on their own; simulated ones step here."""

    @property
    def world_from_base(self) -> np.ndarray | None:
        """``T_world_base`` where the backend knows it exactly (a simulator); None for real arms."""
        return None
