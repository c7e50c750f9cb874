"""Experiment, not used by igen-deploy: the franky arm tracks a virtual copy of the training controller.

The training simulator's operational-space controller moves the hand only part of the way to
each period's goal (``goal = measured + delta``; kp 150, critical damping, mass-decoupled).
Here a 500 Hz thread integrates that ideal law (the "virtual arm") and streams its position,
velocity and acceleration to franky's ``CartesianImpedanceTrackingMotion``, a stiff torque-level
tracker (no motion generator, so none of its reflexes). When contact holds the real hand back,
the virtual arm is pulled to within ``max_lead`` of it, which bounds the contact force.
``install()`` swaps this into :class:`FrankyArm` for the benchmarks that import it
(docs/benchmarks.md, "The trained policy through the franky driver stack"):

    .venv/bin/python benchmarks/bench_step_response.py --backend franky --virtual-osc --out outputs/step/impedance.json
    .venv/bin/python benchmarks/franky_virtual_osc.py --policy CHECKPOINT|scripted --trials 6 --out OUT.json
"""

from __future__ import annotations

import argparse
import threading
import time

import numpy as np

from lerobot_env_igen.osc import OscGains
from lerobot_robot_igen.backends import franky_arm

_GAINS = OscGains()  # the training controller's, mass-normalised
KP = _GAINS.kp_pos  # [1/s^2]
KD = 2.0 * np.sqrt(KP) * _GAINS.damping_ratio
STIFFNESS = 5000.0  # [N/m] the tracker's, stiff enough that a few N of model error cost ~1 mm
ROTATIONAL_STIFFNESS = 400.0  # [Nm/rad] holds the hand's orientation to ~0.2 degrees
MASS = 3.0  # [kg] task-space inertia assumed for the tracker's critical damping
MAX_LEAD = 0.005  # [m] how far the virtual arm may run ahead of a hand held back by contact
STREAM_PERIOD = 0.002  # [s]


class VirtualArm:
    """The training controller's ideal closed loop, integrated at 1 ms, goal set once a period."""

    def __init__(self, position: np.ndarray, velocity: np.ndarray, rotation: np.ndarray) -> None:
        self.p, self.v, self.goal, self.rotation = position.copy(), velocity.copy(), position.copy(), rotation
        self.lock = threading.Lock()
        self._time = time.perf_counter()

    def advance(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        now = time.perf_counter()
        with self.lock:
            elapsed, self._time = min(now - self._time, 0.1), now
            steps = max(1, int(np.ceil(elapsed / 0.001)))
            for _ in range(steps):
                accel = KP * (self.goal - self.p) - KD * self.v
                self.v = self.v + accel * elapsed / steps
                self.p = self.p + self.v * elapsed / steps
            return self.p.copy(), self.v.copy(), KP * (self.goal - self.p) - KD * self.v, self.rotation.copy()


def _stream(arm, motion, virtual: VirtualArm, stop: threading.Event) -> None:
    franky = arm._franky
    while not stop.is_set():
        p, v, a, rotation = virtual.advance()
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = rotation, p
        reference = franky.CartesianReference(
            franky.Affine(T), franky.Twist(v, np.zeros(3)), franky.TwistAcceleration(a, np.zeros(3))
        )
        try:
            motion.set_reference(reference)
        except Exception:  # noqa: BLE001 - the motion ended (stop, reflex): the next target restarts it
            return
        time.sleep(STREAM_PERIOD)


def _send_target(self, T_base_site: np.ndarray) -> None:
    franky = self._franky
    T_tcp = np.asarray(T_base_site, dtype=float) @ self._T_site_tcp
    state = self.robot.current_cartesian_state
    T_meas = np.asarray(state.pose.end_effector_pose.matrix)
    v_meas = np.asarray(state.velocity.end_effector_twist.linear)
    virtual = getattr(self, "_virtual", None)
    if virtual is None:
        virtual = VirtualArm(T_meas[:3, 3], v_meas, T_tcp[:3, :3])
        damping = 2.0 * np.sqrt(STIFFNESS * MASS)
        motion = franky.CartesianImpedanceTrackingMotion(
            translational_stiffness=STIFFNESS, rotational_stiffness=ROTATIONAL_STIFFNESS, gains_time_constant=0.005
        )
        motion.set_gains(
            franky.CartesianImpedanceGains.diagonal(
                np.array([STIFFNESS] * 3 + [ROTATIONAL_STIFFNESS] * 3),
                np.array([damping] * 3 + [2.0 * np.sqrt(ROTATIONAL_STIFFNESS)] * 3),
            )
        )
        motion.set_reference(franky.CartesianReference(franky.Affine(np.ascontiguousarray(T_meas))))
        self._call("the impedance motion", self.robot.move, motion, asynchronous=True)
        self._virtual, self._virtual_stop = virtual, threading.Event()
        self._virtual_thread = threading.Thread(target=_stream, args=(self, motion, virtual, self._virtual_stop))
        self._virtual_thread.start()
    else:
        virtual.advance()
    with virtual.lock:
        lead = virtual.p - T_meas[:3, 3]
        if np.linalg.norm(lead) > MAX_LEAD:
            virtual.p = T_meas[:3, 3] + lead * (MAX_LEAD / np.linalg.norm(lead))
            virtual.v = v_meas.copy()
        virtual.goal, virtual.rotation = T_tcp[:3, 3].copy(), T_tcp[:3, :3].copy()


def _end_stream(self) -> bool:
    if getattr(self, "_virtual", None) is None:
        return False
    self._virtual_stop.set()
    self._virtual_thread.join(1.0)
    self._virtual = None
    return True


def install() -> None:
    """Make every FrankyArm in this process stream through the virtual arm."""
    stop, move_home = franky_arm.FrankyArm.stop, franky_arm.FrankyArm.move_home

    def patched_stop(self) -> None:
        _end_stream(self)
        stop(self)

    def patched_move_home(self) -> None:
        if _end_stream(self):
            self.robot.stop()
        move_home(self)

    franky_arm.FrankyArm.send_target = _send_target
    franky_arm.FrankyArm.stop = patched_stop
    franky_arm.FrankyArm.move_home = patched_move_home


def main() -> None:
    from igen_lerobot.training.policy_source import PolicySourceConfig
    from lerobot_robot_igen.backends.franky_arm import FrankyArmConfig
    from lerobot_robot_igen.config_deploy import DeployConfig, FrankySimPerceptionConfig
    from lerobot_robot_igen.deploy import deploy

    parser = argparse.ArgumentParser(description="igen-deploy on franky-sim through this tracker")
    parser.add_argument("--policy", required=True, help="a checkpoint's pretrained_model folder, or 'scripted'")
    parser.add_argument("--trials", type=int, default=6)
    parser.add_argument("--out", required=True, help="the JSON report")
    parser.add_argument("--host", default="127.0.0.2", help="franky-sim's address")
    parser.add_argument("--scene-port", type=int, default=7711, help="franky-sim's scene channel (serve.py)")
    args = parser.parse_args()
    install()
    cfg = DeployConfig(
        robot=FrankyArmConfig(host=args.host),
        perception=FrankySimPerceptionConfig(port=args.scene_port),
        trials=args.trials,
        policy=PolicySourceConfig(path=None if args.policy == "scripted" else args.policy),
        output=args.out,
    )
    report = deploy(cfg)
    print(f"{report['deployment']['successes']}/{args.trials}", [t["revealed_at"] for t in report["per_trial"]])


if __name__ == "__main__":
    main()
