"""The training simulator's end-effector controller, run as a model for a real arm to follow.

A policy trained in simulation is closed-loop on its own motion: every 50 ms it says "move by d
from where the hand is now", and the simulator's operational-space controller (kp 150, critical
damping, mass-decoupled: :class:`lerobot_env_igen.osc.OscGains`) moves the hand only about a
quarter of d within the period and stops it within two. An arm that moves differently per period
changes what the policy sees next and so what it does (docs/benchmarks.md: a jerk-limited
trajectory planner at the dynamics a real Franka tolerates lags, then coasts 1.2 cm past a stop).

:class:`TrainingController` integrates that ideal law at 1 ms from the period's goal; the arm's
own stiff tracker follows its position, velocity and acceleration. When contact holds the real
hand back, the model is pulled to within ``max_lead`` of it, which bounds the force the tracker
builds (``stiffness * max_lead``) and keeps the model from running away from the hand.
"""

from __future__ import annotations

import threading

import numpy as np

SUBSTEP = 0.001  # [s] integration step of the model
MAX_ELAPSED = 0.1  # [s] a longer gap (a stall) is integrated as this much: never a leap


class TrainingController:
    """Critically damped point mass driven towards a goal; thread-safe, clocked by the caller."""

    def __init__(self, kp: float, damping_ratio: float, position: np.ndarray, velocity: np.ndarray, now: float) -> None:
        if kp <= 0 or damping_ratio <= 0:
            raise ValueError(f"kp and damping_ratio must be > 0, got {kp} and {damping_ratio}")
        self.kp = float(kp)
        self.kd = 2.0 * np.sqrt(self.kp) * float(damping_ratio)
        self.position = np.asarray(position, dtype=float).copy()
        self.velocity = np.asarray(velocity, dtype=float).copy()
        self.goal = self.position.copy()
        self._time = now
        self._lock = threading.Lock()

    def _acceleration(self) -> np.ndarray:
        return self.kp * (self.goal - self.position) - self.kd * self.velocity

    def advance(self, now: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Integrate up to ``now``; returns position, velocity and acceleration there."""
        with self._lock:
            elapsed = min(max(now - self._time, 0.0), MAX_ELAPSED)
            self._time = now
            steps = int(np.ceil(elapsed / SUBSTEP))
            for _ in range(steps):
                self.velocity = self.velocity + self._acceleration() * (elapsed / steps)
                self.position = self.position + self.velocity * (elapsed / steps)
            return self.position.copy(), self.velocity.copy(), self._acceleration()

    def set_goal(
        self, goal: np.ndarray, measured: np.ndarray, measured_velocity: np.ndarray, max_lead: float, now: float
    ) -> None:
        """The period's goal (measured hand + the policy's delta, as in training).

        First catches the model up to ``now``; a model more than ``max_lead`` ahead of the measured
        hand (contact holds the hand) is pulled back to that distance and takes the hand's velocity.
        """
        self.advance(now)
        with self._lock:
            lead = self.position - np.asarray(measured, dtype=float)
            distance = float(np.linalg.norm(lead))
            if distance > max_lead:
                self.position = measured + lead * (max_lead / distance)
                self.velocity = np.asarray(measured_velocity, dtype=float).copy()
            self.goal = np.asarray(goal, dtype=float).copy()
