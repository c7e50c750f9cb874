"""Per-episode randomisation of what a deployed arm changes (``--env.randomize.*``), off by default.

A policy trained on one simulated arm learns that arm's quirks: how fast it answers a new goal, how
late, how its hand is tilted, how exactly its pose and the objects' poses are known. A real Franka
and its camera differ in each, so generation can randomise them, as domain randomisation does:
every episode draws its own values from its seed, from a random stream of its own, so turning
randomisation off (the default) leaves every scene, error and rollout bit-identical to a run
without it. The draw is recorded in the dataset's ``meta/igen.json`` (``origin.randomization``) and
said on its card.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from igen_lerobot.core.exceptions import ConfigError

__all__ = ["ArmRandomization", "ArmDraw", "NO_DRAW"]

# The stream the draw takes from each episode's seed; another number would give other arms for the same scenes.
RANDOMIZATION_STREAM = 0x7A11


@dataclass(frozen=True)
class ArmDraw:
    """One episode's arm: what :class:`~lerobot_env_igen.panda.PandaArm` and the observation apply."""

    kp_scale: float = 1.0  # factor on the OSC stiffness (damping stays critical): the step response
    latency: float = 0.0  # [s] how long into each control period the previous goal is still tracked
    tilt: np.ndarray = field(default_factory=lambda: np.eye(3))  # world-frame rotation on the held hand orientation
    eef_pos_noise: float = 0.0  # [m] std of the noise on the observed hand position
    object_rot_noise: float = 0.0  # [rad] std per axis of the rotation noise on the observed object poses
    noise_seed: int = 0  # seeds the observation noise of this episode

    @property
    def is_identity(self) -> bool:
        observed_exactly = self.eef_pos_noise == 0.0 and self.object_rot_noise == 0.0
        return self.kp_scale == 1.0 and self.latency == 0.0 and observed_exactly and _is_eye(self.tilt)


NO_DRAW = ArmDraw()


def _is_eye(rotation: np.ndarray) -> bool:
    return bool(np.array_equal(rotation, np.eye(3)))


def rotation_noise(rng: np.random.Generator, std_rad: float) -> np.ndarray:
    """A small random rotation: its rotation vector Gaussian with ``std_rad`` per axis (a pose estimate's error)."""
    vector = rng.normal(0.0, std_rad, 3)
    angle = float(np.linalg.norm(vector))
    return _axis_angle(vector / angle, angle) if angle > 0.0 else np.eye(3)


def _axis_angle(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues' rotation about the unit ``axis`` by ``angle`` [rad]."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * (k @ k)


@dataclass
class ArmRandomization:
    """Ranges the episode's arm is drawn from; each default is "as the training arm is".

    Example: ``--env.randomize.kp_scale='[0.5,1.5]' --env.randomize.latency='[0,0.04]'
    --env.randomize.hand_tilt_deg=3 --env.randomize.eef_pos_noise=0.001 --env.randomize.object_rot_noise_deg=1``
    """

    kp_scale: tuple[float, float] = (1.0, 1.0)  # uniform range of the OSC stiffness factor (robosuite's kp 150 x)
    latency: tuple[float, float] = (0.0, 0.0)  # [s] uniform range of the action latency (< one control period)
    hand_tilt_deg: float = 0.0  # [deg] largest constant tilt of the held hand orientation (axis uniform in the plane)
    eef_pos_noise: float = 0.0  # [m] std of Gaussian noise on the observed hand position, new every step
    # [deg] std per axis of a random rotation on each observed object pose, new every step: a camera's
    # pose estimate (the D415 + ICP cube pose errs by about 1 deg). A task whose objects never turn in
    # its data gives their orientation a std near 0, so without it a 1 deg estimate error reaches the
    # policy as tens of standard deviations (docs/benchmarks.md, "The rendered camera path")
    object_rot_noise_deg: float = 0.0

    def check(self, control_period: float, holds_orientation: bool) -> None:
        """Refuse a range that cannot be drawn, by its flag, with the fix."""
        for flag, (low, high) in (("kp_scale", self.kp_scale), ("latency", self.latency)):
            if not (np.isfinite(low) and np.isfinite(high) and low <= high):
                raise ConfigError(f"env.randomize.{flag}={[low, high]} must be a range [low, high] with low <= high")
        if self.kp_scale[0] <= 0.0:
            raise ConfigError(f"env.randomize.kp_scale={list(self.kp_scale)} must be > 0 (a factor on the stiffness)")
        if self.latency[0] < 0.0 or self.latency[1] >= control_period:
            raise ConfigError(
                f"env.randomize.latency={list(self.latency)} [s] must lie in [0, {control_period}) (one control "
                "period): a longer delay would drop goals, not delay them"
            )
        if not 0.0 <= self.hand_tilt_deg <= 15.0:
            raise ConfigError(f"env.randomize.hand_tilt_deg={self.hand_tilt_deg} must be in [0, 15] degrees")
        if self.hand_tilt_deg and not holds_orientation:
            raise ConfigError(
                "env.randomize.hand_tilt_deg applies to position-only tasks (the arm holds the hand's orientation); "
                "this task's policy commands orientation itself: leave it at 0"
            )
        if not (np.isfinite(self.eef_pos_noise) and self.eef_pos_noise >= 0.0):
            raise ConfigError(f"env.randomize.eef_pos_noise={self.eef_pos_noise} [m] must be >= 0")
        if not 0.0 <= self.object_rot_noise_deg <= 10.0:
            raise ConfigError(
                f"env.randomize.object_rot_noise_deg={self.object_rot_noise_deg} must be in [0, 10] degrees"
            )

    @property
    def enabled(self) -> bool:
        moved = tuple(self.kp_scale) != (1.0, 1.0) or tuple(self.latency) != (0.0, 0.0)
        return moved or bool(self.hand_tilt_deg or self.eef_pos_noise or self.object_rot_noise_deg)

    def draw(self, seed: int) -> ArmDraw:
        """The arm of the episode with ``seed`` (the identity when nothing is randomised)."""
        if not self.enabled:
            return NO_DRAW
        rng = np.random.default_rng((int(seed), RANDOMIZATION_STREAM))
        kp_scale = float(rng.uniform(*self.kp_scale))
        latency = float(rng.uniform(*self.latency))
        heading = rng.uniform(0.0, 2.0 * np.pi)
        angle = np.deg2rad(self.hand_tilt_deg) * float(rng.uniform(0.0, 1.0))
        tilt = _axis_angle(np.array([np.cos(heading), np.sin(heading), 0.0]), angle) if angle else np.eye(3)
        noise_seed = int(rng.integers(2**31))
        object_rot_noise = float(np.deg2rad(self.object_rot_noise_deg))
        return ArmDraw(kp_scale, latency, tilt, float(self.eef_pos_noise), object_rot_noise, noise_seed)

    def describe(self) -> dict | None:
        """What the dataset's metadata records (None when off)."""
        if not self.enabled:
            return None
        return {
            "kp_scale": list(self.kp_scale),
            "latency_s": list(self.latency),
            "hand_tilt_deg": self.hand_tilt_deg,
            "eef_pos_noise_m": self.eef_pos_noise,
            **({"object_rot_noise_deg": self.object_rot_noise_deg} if self.object_rot_noise_deg else {}),
            "per": "episode, drawn from its seed",
        }
