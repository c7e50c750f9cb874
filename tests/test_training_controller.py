"""The model of the training controller that the franky impedance path follows: it moves per period as
the training simulator's arm does, and it never runs away from a hand that contact holds back."""

from __future__ import annotations

import numpy as np
import pytest

from lerobot_env_igen.osc import OscGains
from lerobot_robot_igen.arm.config_franky_arm import FrankyArmConfig
from lerobot_robot_igen.arm.mujoco_arm import MujocoArm
from lerobot_robot_igen.arm.training_controller import TrainingController

PERIOD = 0.05
STEP_X = [np.array([0.01, 0.0, 0.0])] * 12 + [np.zeros(3)] * 4  # 1 cm per period, then stop


def model_run(deltas):
    model = TrainingController(150.0, 1.0, np.zeros(3), np.zeros(3), now=0.0)
    positions, now = [model.position.copy()], 0.0
    for d in deltas:
        model.set_goal(model.position + d, model.position, model.velocity, max_lead=1.0, now=now)
        now += PERIOD
        positions.append(model.advance(now)[0])
    return np.diff(np.asarray(positions), axis=0)


def mujoco_run(deltas):
    arm = MujocoArm()
    arm.connect()
    try:
        arm.move_home()
        positions = []
        for d in deltas:
            T = np.array(arm.read_state().T_base_eef)
            positions.append(T[:3, 3].copy())
            T[:3, 3] += d
            arm.send_target(T)
            arm.sync(PERIOD)
        positions.append(arm.read_state().T_base_eef[:3, 3])
    finally:
        arm.disconnect()
    return np.diff(np.asarray(positions), axis=0)


def test_the_model_moves_per_period_as_the_training_arm_does():
    """Same commands, per-period displacement within 1 mm of the MuJoCo arm (whose controller it models:
    a quarter of d per period, stopped within two; measured 0.8 mm worst, from the arm's joint damping and
    null-space pull). The franky trajectory path is 2.3 mm off at worst and coasts 1 cm: it would fail."""
    model, mujoco = model_run(STEP_X), mujoco_run(STEP_X)
    gap = np.linalg.norm(model - mujoco, axis=1)
    assert gap.max() < 0.001, np.round(gap * 1000, 2)
    assert 0.02 < np.linalg.norm(model[:12].sum(axis=0)) < 0.035  # 12 periods of 1 cm asked: about 3 cm moved
    assert np.linalg.norm(model[12:].sum(axis=0)) < 0.002  # and it stops: under 2 mm after the last delta


def test_the_driver_defaults_are_the_training_controllers_gains():
    gains, cfg = OscGains(), FrankyArmConfig()
    assert (cfg.training_kp, cfg.training_damping_ratio) == (gains.kp_pos, gains.damping_ratio)


def test_a_hand_held_back_keeps_the_model_within_max_lead():
    """Contact holds the hand at the origin while the goal keeps asking 3 cm further: the model stays
    within max_lead of the hand (so the tracker's push stays under stiffness * max_lead)."""
    model = TrainingController(150.0, 1.0, np.zeros(3), np.zeros(3), now=0.0)
    hand = np.zeros(3)
    now = 0.0
    for _ in range(40):
        model.set_goal(hand + [0.0, 0.0, -0.03], hand, np.zeros(3), max_lead=0.005, now=now)
        now += PERIOD
        position, _, _ = model.advance(now)
        assert np.linalg.norm(model.position - hand) <= 0.03  # bounded by the goal within a period
    model.set_goal(hand, hand, np.zeros(3), max_lead=0.005, now=now)
    assert np.linalg.norm(model.position - hand) <= 0.005 + 1e-12
    np.testing.assert_allclose(model.velocity, 0.0)  # takes the held hand's velocity


def test_a_stall_is_not_integrated_as_a_leap():
    model = TrainingController(150.0, 1.0, np.zeros(3), np.zeros(3), now=0.0)
    model.set_goal(np.array([0.03, 0.0, 0.0]), np.zeros(3), np.zeros(3), max_lead=1.0, now=0.0)
    once = model.advance(10.0)[0]  # ten seconds without a tick: integrated as 0.1 s
    assert 0.0 < once[0] < 0.03


@pytest.mark.parametrize(
    "field, value",
    [
        ("controller", "ruckig"),
        ("tracker_stiffness", 0.0),
        ("max_lead", -1.0),
        ("grasp_width", -0.01),
        ("grasp_width", 0.08),
        ("grasp_tolerance", 0.0),
    ],
)
def test_bad_controller_settings_name_the_flag(field, value):
    from igen_lerobot.core.exceptions import ConfigError

    with pytest.raises(ConfigError, match=f"--robot.{field}"):
        FrankyArmConfig(**{field: value})
    with pytest.raises(ValueError, match="kp"):
        TrainingController(0.0, 1.0, np.zeros(3), np.zeros(3), now=0.0)
