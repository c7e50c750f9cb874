"""A real Franka (FR3 or Panda) through franky-control, behind the driver protocol.

How the 20 Hz stream reaches the arm depends on ``controller``:

* ``impedance`` (default): each period's target is the goal of a model of the training
  simulator's controller (``training_controller``), which franky's Cartesian impedance tracker
  follows in torque mode (``franky_tracker``). The hand then moves per period as it did in the
  training simulator, and torque control raises none of the motion generator's reflexes. The
  model is kept within ``max_lead`` of the hand and the tracker's position and orientation
  errors are clipped, which bounds the push on an obstacle and the wrist's torque. It has run on
  franky-sim and franka-sim, never on a real arm.
* ``trajectory``: every period the loop sends an *absolute* Cartesian target as an asynchronous
  ``CartesianMotion``; franky's online trajectory generator (Ruckig) plans a jerk-limited path to
  it within the arm's limits scaled by ``relative_dynamics_factor`` (velocity 0.3, acceleration
  and jerk 0.05). Absolute, because franky's *relative* Cartesian motions are expressed in the
  end-effector frame, not the base frame the loop uses. Measured (docs/benchmarks.md): it lags,
  then coasts 1.2 cm past a stop, a trained policy fails on it, and a trained policy's own stream
  (deltas that turn every period) trips the arm's acceleration-discontinuity reflex even at 5%
  acceleration and jerk. Scripted motions, whose targets change smoothly, run well on it.

Moves home are always trajectory motions (a planned path, then the streaming starts afresh).

Frames: franky reports the flange-mounted hand's TCP (``end_effector_pose``) in the base frame;
the policy's end-effector frame is robosuite's grip site, the same point rotated 90 degrees
about the approach axis (``tcp_to_site_rotation``). Never import franky and pylibfranka in
one process: both bundle libfranka.
"""

from __future__ import annotations

import logging
import threading
import time

import numpy as np

from lerobot_robot_igen.arm.config_franky_arm import FrankyArmConfig
from lerobot_robot_igen.arm.driver import ArmDriver, ArmState, ConnectionLostError, DriverError, MotionTimeoutError
from lerobot_robot_igen.arm.franky_tracker import ImpedanceTracker
from lerobot_robot_igen.arm.gripper_worker import GripperWorker

logger = logging.getLogger(__name__)

# franky's top-down hand in the base frame (x forward, fingers along base y, z down)
TOP_DOWN_TCP = ((1.0, 0.0, 0.0), (0.0, -1.0, 0.0), (0.0, 0.0, -1.0))

_STILL_RUNNING: list = []  # gripper workers that outlived their driver, kept so their threads never see freed memory


class FrankyArm(ArmDriver):
    """The franky-control backend."""

    def __init__(self, config: FrankyArmConfig) -> None:
        self.config = config
        self.robot = None
        self.gripper = None
        self._franky = None
        self._gripper_closed: bool | None = None  # the state last asked for
        self._gripper_worker: GripperWorker | None = None
        self._tracker: ImpedanceTracker | None = None
        self._home_joints: np.ndarray | None = None  # where the first Cartesian move home ended
        self._home_reached: np.ndarray | None = None  # the hand's position there [m] (base frame)
        self._T_tcp_site = np.eye(4)
        self._T_tcp_site[:3, :3] = np.asarray(config.tcp_to_site_rotation, dtype=float)
        self._T_site_tcp = np.linalg.inv(self._T_tcp_site)

    # ------------------------------------------------------------------ errors
    def _fail(self, what: str, error: Exception) -> DriverError:
        franky = self._franky
        text = f"{type(error).__name__}: {error}"
        network = franky is not None and isinstance(error, franky.NetworkException)
        # libfranka also reports a dead link from the state stream as a bare "Net Exception" / TCP / UDP error
        if network or any(word in str(error) for word in ("Net Exception", "TCP", "UDP", "Connection")):
            return ConnectionLostError(
                f"robot at {self.config.host} unreachable while {what} ({text}); check the network cable, that "
                "the arm is unlocked with FCI enabled in Desk, and that no other program holds control"
            )
        return DriverError(f"the robot refused {what}: {text} (a reflex? recover() clears it)")

    def _call(self, what: str, fn, *args, **kwargs):
        if self.robot is None:
            raise ConnectionLostError(f"not connected to the robot at {self.config.host}: call connect() first")
        try:
            return fn(*args, **kwargs)
        except Exception as error:  # franky raises its own exception types; map them to ours
            if isinstance(error, DriverError):
                raise
            raise self._fail(what, error) from error

    # ------------------------------------------------------------------ connection
    def connect(self) -> None:
        import franky

        self._franky = franky
        cfg = self.config
        robot, gripper = self._open_connections(franky)
        self.robot, self.gripper = robot, gripper
        self._gripper_worker = GripperWorker(
            close=lambda: gripper.grasp(
                cfg.grasp_width, cfg.gripper_speed, cfg.grasp_force, cfg.grasp_tolerance, cfg.grasp_tolerance
            ),
            open_=lambda: gripper.move(cfg.open_width, cfg.gripper_speed),
        )
        if cfg.controller == "impedance":
            self._tracker = ImpedanceTracker(robot, franky, cfg, self._call)
        self._call("error recovery", robot.recover_from_errors)
        robot.relative_dynamics_factor = franky.RelativeDynamicsFactor(
            cfg.velocity_factor, cfg.acceleration_factor, cfg.jerk_factor
        )
        self._gripper_closed = None

    def _open_connections(self, franky):
        """Open franky's Robot and Gripper in a thread, so that a silent arm costs connect_timeout, not forever.

        A connection that answers after the deadline is dropped at once (freeing it closes it), so it
        never holds the arm, which takes one client at a time.
        """
        cfg = self.config
        result: dict = {}
        gave_up = threading.Event()

        def open_both() -> None:
            try:
                robot = franky.Robot(cfg.host, realtime_config=franky.RealtimeConfig.Ignore)
                gripper = franky.Gripper(cfg.host)
            except Exception as error:  # franky raises its own exception types; reported below
                result["error"] = error
                return
            if not gave_up.is_set():
                result["connections"] = (robot, gripper)

        opening = threading.Thread(target=open_both, name="franky-connect", daemon=True)
        opening.start()
        opening.join(cfg.connect_timeout)
        if opening.is_alive():
            gave_up.set()
            raise ConnectionLostError(
                f"the robot at {cfg.host} did not answer within {cfg.connect_timeout:g} s (--robot.connect_timeout); "
                "check the address (--robot.host), that FCI is enabled in Desk, and that no other program holds "
                "the arm"
            )
        if "error" in result:
            error = result["error"]
            raise ConnectionLostError(
                f"cannot connect to the robot at {cfg.host} ({error}); check the address (--robot.host), the "
                "network cable, and that FCI is enabled in Desk"
            ) from error
        return result["connections"]

    def disconnect(self) -> None:
        if self.robot is not None:
            try:
                self.stop()
            except DriverError as error:  # a reflex: the arm is already stopped
                logger.warning("stopping before disconnect failed: %s", error)
        if self._gripper_worker is not None:
            # a gripper command still running uses the Gripper from the worker's thread: freeing the
            # Gripper under it crashes the process, so let it finish (bounded), and if it does not,
            # keep both alive for the life of the process
            if not self._gripper_worker.close(self.config.gripper_timeout):
                _STILL_RUNNING.append((self.gripper, self._gripper_worker))
            self._gripper_worker = None
        # nothing may keep the franky.Robot alive: its connection closes only when it is freed, and the
        # arm (franky-sim too) takes one client at a time, so a kept reference blocks the next connect()
        self._tracker = None
        self.robot = self.gripper = None

    @property
    def is_connected(self) -> bool:
        return self.robot is not None

    # ------------------------------------------------------------------ state
    def robot_time(self) -> float:
        """The arm's own clock [s]: libfranka's robot time, the time stamp of its last state."""
        return float(self._call("a state read", lambda: self.robot.state.time.to_sec()))

    def read_state(self) -> ArmState:
        robot = self.robot
        pose = self._call("a state read", lambda: robot.current_cartesian_state.pose.end_effector_pose)
        joints = self._call("a state read", lambda: np.asarray(robot.current_joint_positions, dtype=float))
        force = self._call("a state read", lambda: np.asarray(robot.state.O_F_ext_hat_K, dtype=float)[:3])
        width = self._call("a gripper read", lambda: float(self.gripper.width))
        return ArmState(
            T_base_eef=np.asarray(pose.matrix, dtype=float) @ self._T_tcp_site,
            joint_positions=joints,
            gripper_width=width,
            external_force=float(np.linalg.norm(force)),
            timestamp=time.monotonic(),
        )

    # ------------------------------------------------------------------ commands
    def _motion(self, T_base_site: np.ndarray, factor=None):
        franky = self._franky
        T_base_tcp = np.asarray(T_base_site, dtype=float) @ self._T_site_tcp
        target = franky.Affine(np.ascontiguousarray(T_base_tcp))
        if factor is None:
            return franky.CartesianMotion(target, franky.ReferenceType.Absolute)
        return franky.CartesianMotion(target, franky.ReferenceType.Absolute, relative_dynamics_factor=factor)

    def send_target(self, T_base_eef: np.ndarray) -> None:
        if self._tracker is not None:
            self._tracker.send(np.asarray(T_base_eef, dtype=float) @ self._T_site_tcp)
            return
        motion = self._motion(T_base_eef)
        self._call("a Cartesian target", self.robot.move, motion, asynchronous=True)

    def set_gripper(self, closed: bool) -> None:
        """Ask for the fingers closed (a grasp) or open; returns at once (see ``gripper_worker``)."""
        if self._gripper_worker is None:
            raise ConnectionLostError(f"not connected to the robot at {self.config.host}: call connect() first")
        error = self._gripper_worker.take_error()
        if error is not None:
            raise self._fail("a gripper command", error) from error
        if closed != self._gripper_closed:
            self._gripper_worker.want(closed)
            self._gripper_closed = closed

    def wait_gripper(self, timeout: float) -> None:
        """Block until the last gripper state asked for is reached (the move home, tests)."""
        worker = self._gripper_worker
        if worker is None:
            return
        if not worker.wait_idle(timeout):
            raise DriverError(f"the gripper did not finish its command within {timeout} s")
        if (error := worker.take_error()) is not None:
            raise self._fail("a gripper command", error) from error

    def stop(self) -> None:
        if self.robot is None:
            return
        tracking = self._tracker is not None and self._tracker.end()
        try:
            self._call("a stop", self.robot.stop)
        except ConnectionLostError as error:
            # The arm's controller stops by itself when the stream of commands breaks off
            # (libfranka's communication constraints); nothing more can be sent to it.
            logger.warning("cannot send stop: %s; the arm halts on its own when it loses the connection", error)
            return
        if tracking:
            # a torque motion ends at the next cycle after the stop; wait for it, or the connection (and a
            # new one to the same arm) stays held by a motion still running
            try:
                self.robot.join_motion(self.config.settle_timeout)
            except Exception as error:  # noqa: BLE001 - the stop preempts it: that is how it ends
                if "preempted" not in str(error):
                    raise self._fail("the stop", error) from error

    def recover(self) -> None:
        self._call("error recovery", self.robot.recover_from_errors)

    def _finish_last_motion(self) -> None:
        """Let the last asynchronous target finish (bounded) and clear any error it left.

        A motion's failure surfaces at the next command: the move home would inherit the last
        target's error instead of starting from a still, error-free arm.
        """
        if self._tracker is not None and self._tracker.end():
            self._call("a stop", self.robot.stop)  # the tracking motion never ends by itself
        try:
            self.robot.join_motion(self.config.settle_timeout)
        except Exception as error:  # noqa: BLE001 - any franky error of the finished motion
            failure = self._fail("the last target", error)
            if isinstance(failure, ConnectionLostError):
                raise failure from error
            if "preempted" in str(error):  # the stop above (or a newer motion) ended it, as intended
                logger.debug("the last motion was preempted before the move home")
            else:
                logger.warning("the last target before the move home ended with %s: %s", type(error).__name__, error)
        self._call("error recovery", self.robot.recover_from_errors)

    def move_home(self) -> None:
        cfg = self.config
        T_home = np.eye(4)
        T_home[:3, :3] = np.asarray(TOP_DOWN_TCP) @ self._T_tcp_site[:3, :3]  # the site's top-down pose
        T_home[:3, 3] = cfg.home_position
        factor = self._franky.RelativeDynamicsFactor(cfg.home_velocity_factor, cfg.acceleration_factor, cfg.jerk_factor)
        self._finish_last_motion()
        try:
            self._move_home_to(T_home[:3, 3], "the move home", self._motion(T_home, factor))
        except (ConnectionLostError, MotionTimeoutError):
            raise
        except DriverError as error:
            # planned from an arm still pushing on something (a trial ending in contact) the move can
            # fail (ruckig -101); once the arm has come to rest and errors are cleared it plans
            logger.warning("%s; recovering and trying the move home once more", error)
            self._finish_last_motion()
            try:
                self._move_home_to(T_home[:3, 3], "the move home", self._motion(T_home, factor))
            except DriverError as again:
                if self._home_joints is None or isinstance(again, (ConnectionLostError, MotionTimeoutError)):
                    raise
                # a Cartesian plan can fail outright from an awkward pose (ruckig -110 seen after a
                # policy drove the hand to the workspace corner); the joint-space path home does not
                logger.warning("%s; moving home in joint space instead", again)
                self._finish_last_motion()
                joints = self._franky.JointMotion(
                    self._franky.JointState(self._home_joints), relative_dynamics_factor=factor
                )
                self._move_home_to(self._home_reached, "the move home (joint space)", joints)
        if self._home_joints is None:
            self._home_joints = self._call(
                "a state read", lambda: np.asarray(self.robot.current_joint_positions, float)
            )
            self._home_reached = self.read_state().eef_position.copy()
        self.set_gripper(False)
        self.wait_gripper(2 * self.config.gripper_timeout)  # a grasp still settling, then the opening

    def _move_home_to(self, home: np.ndarray, what: str, motion) -> None:
        """A blocking move home, checked where it ended: a trial must never start away from home.

        franky can return from a motion the arm refused without an error (the error surfaces at the
        next command); the arm then stays where the last trial left it. Seen in a rehearsal: a trial
        began with the hand 50 cm from home, outside the workspace, and the safety layer stopped it.
        """
        self._move_and_wait(what, motion)
        reached = self.read_state().eef_position
        off = float(np.linalg.norm(reached - home))
        if off > self.config.home_tolerance:
            raise DriverError(
                f"{what} ended {100 * off:.1f} cm from home, with the hand at {np.round(reached, 3).tolist()} m "
                f"(base frame; --robot.home_tolerance={self.config.home_tolerance:g} m)"
            )

    def _move_and_wait(self, what: str, motion) -> None:
        """A blocking move with a deadline.

        On timeout the arm is told to stop and the caller gets a clear error, instead of a process
        waiting forever on franky's motion thread.
        """
        self._call(what, self.robot.move, motion, asynchronous=True)
        if self._call(what, self.robot.join_motion, self.config.home_timeout):
            return
        try:
            self._call("a stop", self.robot.stop)
        except DriverError as error:
            logger.warning("could not stop after %s timed out: %s", what, error)
        raise MotionTimeoutError(
            f"{what} did not finish within {self.config.home_timeout:g} s (--robot.home_timeout); the arm was "
            "told to stop. Check that the arm (or franky-sim) still answers and nothing blocks the path home."
        )
