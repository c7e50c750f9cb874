"""The franky arm following :class:`TrainingController` with franky's Cartesian impedance tracker.

franky's ``CartesianImpedanceTrackingMotion`` computes joint torques every 1 ms cycle from a
reference pose, twist and acceleration (stiffness, damping, and the task-space inertia times the
reference acceleration). It holds the last reference it was given, so a thread streams the
model's state every ``stream_period``. Torque control has no motion generator, so none of the
motion generator's discontinuity reflexes that a 20 Hz stream of trajectory targets raises
(docs/benchmarks.md); franky limits the torque change per cycle (``max_delta_tau``).
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable

import numpy as np

from lerobot_robot_igen.arm.training_controller import TrainingController

logger = logging.getLogger(__name__)


class ImpedanceTracker:
    """One tracking motion and its streaming thread, started by the first target after a stop."""

    def __init__(self, robot, franky, config, call: Callable) -> None:
        self._robot, self._franky, self._config, self._call = robot, franky, config, call
        self._model: TrainingController | None = None
        self._motion = None
        self._rotation = np.eye(3)
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    @property
    def running(self) -> bool:
        return self._model is not None

    def send(self, T_base_tcp: np.ndarray) -> None:
        """Set the period's goal (a TCP pose, base frame): the model moves towards it, the arm follows."""
        cfg = self._config
        state = self._call("a state read", lambda: self._robot.current_cartesian_state)
        measured = np.asarray(state.pose.end_effector_pose.matrix, dtype=float)
        velocity = np.asarray(state.velocity.end_effector_twist.linear, dtype=float)
        now = time.perf_counter()
        if self._model is not None and not self._call("the impedance tracker", self._running):
            # the motion ended (a reflex, a stop from elsewhere) or refused a reference: raise its error
            self.end()
            self._call("the impedance tracker", self._join_ended)
        if self._model is None:
            self._start(measured, velocity, now)
        self._rotation = np.asarray(T_base_tcp, dtype=float)[:3, :3].copy()
        self._model.set_goal(np.asarray(T_base_tcp)[:3, 3], measured[:3, 3], velocity, cfg.max_lead, now)

    def _running(self) -> bool:
        """Whether the tracking motion still runs (a cheap flag read, 0.01 ms).

        A reflex ends the motion while franky still takes references for it: without this check the
        loop would stream targets to an arm that stopped, and learn of it only at the move home.
        """
        return bool(self._robot.is_in_control) and self._thread is not None and self._thread.is_alive()

    def _join_ended(self) -> None:
        """Collect an ended motion's outcome: its error (a reflex) is raised; a preemption (a stop) is not one."""
        try:
            self._robot.join_motion(1.0)
        except Exception as error:
            if "preempted" not in str(error):
                raise
            logger.debug("the tracking motion was stopped from elsewhere; a new one starts")

    def _start(self, measured: np.ndarray, velocity: np.ndarray, now: float) -> None:
        franky, cfg = self._franky, self._config
        self._model = TrainingController(cfg.training_kp, cfg.training_damping_ratio, measured[:3, 3], velocity, now)
        self._rotation = measured[:3, :3].copy()
        k, kr = cfg.tracker_stiffness, cfg.tracker_rotational_stiffness
        damping = 2.0 * np.sqrt(k * cfg.tracker_mass)  # critical for the assumed task-space inertia
        motion = franky.CartesianImpedanceTrackingMotion(
            translational_stiffness=k,
            rotational_stiffness=kr,
            rotational_error_clip=np.full(3, cfg.tracker_rotational_error_clip),
            translational_error_clip=np.full(3, cfg.tracker_translational_error_clip),
            gains_time_constant=0.005,
        )
        motion.set_gains(
            franky.CartesianImpedanceGains.diagonal(
                np.array([k] * 3 + [kr] * 3), np.array([damping] * 3 + [2.0 * np.sqrt(kr)] * 3)
            )
        )
        motion.set_reference(franky.CartesianReference(franky.Affine(np.ascontiguousarray(measured))))
        self._call("the impedance tracker", self._robot.move, motion, asynchronous=True)
        self._motion = motion
        self._stop.clear()
        self._thread = threading.Thread(target=self._stream, name="impedance-reference", daemon=True)
        self._thread.start()

    def _stream(self) -> None:
        franky, period = self._franky, self._config.stream_period
        model, motion = self._model, self._motion
        while not self._stop.wait(period):
            position, velocity, acceleration = model.advance(time.perf_counter())
            T = np.eye(4)
            T[:3, :3], T[:3, 3] = self._rotation, position
            reference = franky.CartesianReference(
                franky.Affine(T),
                franky.Twist(velocity, np.zeros(3)),
                franky.TwistAcceleration(acceleration, np.zeros(3)),
            )
            try:
                motion.set_reference(reference)
            except Exception as error:  # noqa: BLE001 - the motion ended; the loop's next target reports why
                logger.debug("impedance reference not taken: %s", error)
                return

    def end(self) -> bool:
        """Stop streaming (the caller stops the arm); True if a motion was running."""
        if self._model is None:
            return False
        self._stop.set()
        if self._thread is not None:
            self._thread.join(1.0)
        self._model = self._motion = self._thread = None
        return True
