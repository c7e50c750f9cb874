"""The arm as the deployment loop sees it: task-frame commands, every limit enforced here.

:class:`SafeArm` wraps any :class:`~lerobot_robot_igen.arm.driver.ArmDriver`. It converts between the
task frame (where the policy acts, see :mod:`lerobot_robot_igen.arm.safety`) and the robot base
frame, refuses or limits commands with :class:`~lerobot_robot_igen.arm.safety.SafetyGuard`, and runs
a watchdog thread that stops the arm when no command arrives for ``watchdog_timeout`` seconds
of the arm's clock (wall time on a real arm, simulated time in a rehearsal), even if the loop
itself hangs. Once stopped for a fault it refuses further commands until
:meth:`SafeArm.rearm`, so a fault cannot be driven through.
"""

from __future__ import annotations

import logging
import threading

import numpy as np

from lerobot_robot_igen.arm.driver import ArmDriver, ArmState, DriverError
from lerobot_robot_igen.arm.safety import SafetyGuard, SafetyLimits, SafetyViolationError

logger = logging.getLogger(__name__)


class ArmFaultError(SafetyViolationError):
    """The arm was stopped for a fault earlier; it takes no commands until re-armed."""


class SafeArm:
    """Task-frame interface to an arm with workspace, speed, action and watchdog limits."""

    def __init__(
        self,
        driver: ArmDriver,
        world_from_base: np.ndarray,
        limits: SafetyLimits | None = None,
        max_delta: float = 0.03,
        refuse_delta: float = 0.10,
        watchdog: bool = True,
        goal_rotation: np.ndarray | None = None,
    ) -> None:
        self.driver = driver
        # the orientation every target asks for (task frame), as the training controller's goal does;
        # None keeps the measured one, which lets any drift of a compliant arm stand uncorrected
        self.goal_rotation = None if goal_rotation is None else np.asarray(goal_rotation, dtype=float)
        self.T_world_base = np.asarray(world_from_base, dtype=float)
        self.T_base_world = np.linalg.inv(self.T_world_base)
        self.guard = SafetyGuard(limits or SafetyLimits())
        self.max_delta = float(max_delta)
        self.refuse_delta = float(refuse_delta)
        self.fault: str | None = None
        self.fault_recoverable = False  # only a watchdog stop: the arm stood still, nothing was violated
        self.clamped_targets = 0
        self._gripper_closed: bool | None = None
        self._last_command = float("inf")  # armed by the first command of an episode
        self._lock = threading.Lock()
        self._watchdog_stop = threading.Event()
        self._watchdog: threading.Thread | None = None
        if watchdog:
            self._watchdog = threading.Thread(target=self._watch, name="arm-watchdog", daemon=True)
            self._watchdog.start()

    # ------------------------------------------------------------------ state
    def read(self) -> tuple[ArmState, np.ndarray]:
        """The arm state and ``T_world_eef``; a measured pose outside the workspace is a fault."""
        try:
            state = self.driver.read_state()
        except DriverError as err:
            self.halt(str(err))
            raise
        T_world_eef = self.T_world_base @ state.T_base_eef
        try:
            self.guard.check_position(T_world_eef[:3, 3])
        except SafetyViolationError as err:
            self.halt(str(err))
            raise
        return state, T_world_eef

    def world_to_base(self, T_world: np.ndarray) -> np.ndarray:
        return self.T_base_world @ T_world

    # ------------------------------------------------------------------ commands
    def command(
        self,
        T_world_eef: np.ndarray,
        delta: np.ndarray,
        close_gripper: bool,
        period: float,
        rotation: np.ndarray | None = None,
    ) -> np.ndarray:
        """Move by ``delta`` [m, task frame] from ``T_world_eef`` this period; returns the sent task-frame target.

        The delta is clipped to ``max_delta`` per axis, as the simulator the policy was trained in
        clips it. The target's orientation is ``rotation`` (task frame) when given (a 6-DOF task's
        action sets it), else ``goal_rotation`` when set (the training controller's fixed goal),
        else the measured one. A delta beyond ``refuse_delta`` (no trained policy
        outputs that: a wrong checkpoint or normalisation), a non-finite one, or a target far
        outside the workspace stops the arm and raises :class:`SafetyViolationError`.
        """
        if self.fault is not None:
            raise ArmFaultError(f"the arm was stopped ({self.fault}); it takes no commands until re-armed")
        delta = np.asarray(delta, dtype=float)
        try:
            if delta.shape != (3,) or not np.all(np.isfinite(delta)):
                raise SafetyViolationError(f"action delta {delta.tolist()} is not 3 finite values [m]")
            if rotation is not None:
                rotation = np.asarray(rotation, dtype=float)
                if rotation.shape != (3, 3) or not np.all(np.isfinite(rotation)):
                    raise SafetyViolationError(f"target orientation {rotation.tolist()} is not a finite 3x3 rotation")
            if np.any(np.abs(delta) > self.refuse_delta):
                raise SafetyViolationError(
                    f"action delta {np.round(delta, 4).tolist()} m exceeds refuse_delta={self.refuse_delta} m per axis "
                    f"and step (the policy was trained within +-{self.max_delta} m): is this checkpoint for this task?"
                )
            current = T_world_eef[:3, 3]
            wanted = current + np.clip(delta, -self.max_delta, self.max_delta)
            target_pos = self.guard.filter_target(current, wanted, period)
        except SafetyViolationError as err:
            self.halt(str(err))
            raise
        if not np.allclose(np.clip(wanted, self.guard.limits.workspace_min, self.guard.limits.workspace_max), wanted):
            self.clamped_targets += 1
        target = np.array(T_world_eef, dtype=float)
        if rotation is not None:
            target[:3, :3] = rotation
        elif self.goal_rotation is not None:
            target[:3, :3] = self.goal_rotation
        target[:3, 3] = target_pos
        try:
            with self._lock:
                self.driver.send_target(self.world_to_base(target))
                if close_gripper != self._gripper_closed:
                    self.driver.set_gripper(close_gripper)
                    self._gripper_closed = close_gripper
                self._last_command = self.driver.clock()
        except DriverError as err:
            self.halt(str(err))
            raise
        return target

    def halt(self, reason: str, recoverable: bool = False) -> None:
        """Stop the arm for a fault; commands are refused until :meth:`rearm`."""
        # a hard fault replaces a watchdog stop: it is the reason the user needs to see
        if self.fault is None or (self.fault_recoverable and not recoverable):
            log = logger.warning if recoverable else logger.error
            log("stopping the arm: %s", reason)
            self.fault = reason
            self.fault_recoverable = recoverable
        self._stop_driver()

    def _stop_driver(self) -> None:
        try:
            with self._lock:
                self.driver.stop()
        except DriverError as err:  # the connection may be what failed; stopping must not raise
            logger.warning("stop after a fault failed too: %s", err)

    def rearm(self) -> None:
        """Accept commands again after a fault (a new episode); recovers the driver's error state."""
        self.driver.recover()
        self.fault = None
        self.fault_recoverable = False
        self._gripper_closed = None
        self.clamped_targets = 0
        self._last_command = float("inf")

    def idle(self) -> None:
        """Between episodes: the watchdog must not fire while nobody streams commands."""
        self._last_command = float("inf")

    # ------------------------------------------------------------------ watchdog
    def _watch(self) -> None:
        timeout = self.guard.limits.watchdog_timeout
        while not self._watchdog_stop.wait(min(0.02, timeout / 4)):
            if self.fault is None and self.driver.clock() - self._last_command > timeout:
                self.halt(f"watchdog: no command for more than {timeout} s", recoverable=True)

    def close(self) -> None:
        """Stop the watchdog and the arm (not the connection: the driver's owner closes it)."""
        self._watchdog_stop.set()
        if self._watchdog is not None:
            self._watchdog.join(timeout=1.0)
        self._stop_driver()
