"""Per-episode arm randomisation (``--env.randomize.*``): what a deployed arm changes, from the seed.

Real physics throughout: the step response, the latency and the tilt are measured on the arm, not
read back from the draw.
"""

import json

import draccus
import numpy as np
import pytest

from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.core.task import OBS_STATE
from lerobot_env_igen.arm_randomization import ArmRandomization

SEEDS = range(8)


def block_grasp(**randomize):
    from igen_lerobot.core.env_config import task_config_class

    return task_config_class("block_grasp")(randomize=ArmRandomization(**randomize))


def first_period_travel(env, seed, step_m=0.03):
    """How far the hand moves in the one control period after a sideways goal step of ``step_m``."""
    env.reset(seed)
    start = env.eef_pose()[:3, 3].copy()
    env.step(np.array([0.0, step_m, 0.0, -1.0]))
    return float(env.eef_pose()[1, 3] - start[1])


def test_off_by_default_and_the_draw_never_moves_the_scene_or_the_error():
    assert not block_grasp().randomize.enabled
    plain = block_grasp().make_task_env()
    everything = {"kp_scale": (0.5, 1.5), "latency": (0.0, 0.04), "hand_tilt_deg": 5.0, "eef_pos_noise": 0.002}
    varied = block_grasp(**everything).make_task_env()
    for seed in SEEDS:
        plain.reset(seed)
        varied.reset(seed)
        # its own random stream: the same cube and the same pose error as without randomisation
        np.testing.assert_array_equal(plain.true_object_pose_vector(), varied.true_object_pose_vector())
        np.testing.assert_array_equal(plain.corruption, varied.corruption)
    assert plain.arm_draw.is_identity


def test_draws_repeat_for_a_seed_differ_across_seeds_and_stay_in_range():
    randomize = ArmRandomization(kp_scale=(0.5, 1.5), latency=(0.0, 0.04), hand_tilt_deg=4.0)
    draws = [randomize.draw(seed) for seed in range(200)]
    again = randomize.draw(3)
    assert again.kp_scale == draws[3].kp_scale and again.latency == draws[3].latency
    np.testing.assert_array_equal(again.tilt, draws[3].tilt)
    kp = np.array([d.kp_scale for d in draws])
    latency = np.array([d.latency for d in draws])
    tilt = np.array([np.degrees(np.arccos(np.clip((np.trace(d.tilt) - 1) / 2, -1, 1))) for d in draws])
    assert kp.min() >= 0.5 and kp.max() <= 1.5 and kp.max() - kp.min() > 0.8  # spread over the range
    assert latency.min() >= 0.0 and latency.max() <= 0.04 and latency.max() > 0.03
    assert tilt.max() <= 4.0 + 1e-9 and tilt.max() > 3.0
    for d in draws[:20]:  # a tilt is a rotation about a horizontal axis
        np.testing.assert_allclose(d.tilt @ d.tilt.T, np.eye(3), atol=1e-12)
        axis = np.array([d.tilt[2, 1] - d.tilt[1, 2], d.tilt[0, 2] - d.tilt[2, 0], d.tilt[1, 0] - d.tilt[0, 1]])
        assert abs(axis[2]) < 1e-12


def test_a_softer_or_later_arm_answers_a_goal_step_slower():
    """Tolerances: the training arm moves several mm in its first period; each change at least 20% less."""
    env, seed = block_grasp().make_task_env(), 11
    travel = {}
    for name, randomize in {
        "training": ArmRandomization(),
        "soft": ArmRandomization(kp_scale=(0.4, 0.4)),
        "late": ArmRandomization(latency=(0.03, 0.03)),
        "stiff": ArmRandomization(kp_scale=(1.6, 1.6)),
    }.items():
        env.randomization = randomize  # what the config hands the env; reset draws from it
        travel[name] = first_period_travel(env, seed)
    assert travel["training"] > 0.002, travel
    assert travel["soft"] < 0.8 * travel["training"] and travel["late"] < 0.8 * travel["training"], travel
    assert travel["stiff"] > 1.2 * travel["training"], travel


def test_a_position_only_hand_is_held_at_the_drawn_tilt():
    env = block_grasp(hand_tilt_deg=6.0).make_task_env()
    env.reset(5)
    for _ in range(30):
        env.step(np.array([0.0, 0.0, 0.0, -1.0]))
    drawn = np.degrees(np.arccos((np.trace(env.arm_draw.tilt) - 1) / 2))
    held = env.eef_pose()[:3, :3] @ env.action_space.rotation.T
    angle = np.degrees(np.arccos(np.clip((np.trace(held) - 1) / 2, -1, 1)))
    assert drawn > 0.5
    assert abs(angle - drawn) < 0.5, (angle, drawn)  # the OSC holds the tilted goal within half a degree


def test_observed_hand_position_carries_the_configured_noise():
    env = block_grasp(eef_pos_noise=0.002).make_task_env()
    env.reset(2)
    errors = []
    for _ in range(100):
        env.step(np.array([0.0, 0.0, 0.0, -1.0]))
        errors.append(env.observe()[OBS_STATE][:3] - env.eef_pose()[:3, 3])
    std = float(np.std(errors))
    assert 0.0015 < std < 0.0025, std  # 300 samples: the std within 25% of 2 mm


def test_observed_object_orientation_carries_the_configured_noise_and_leaves_the_hands_alone():
    from scipy.spatial.transform import Rotation

    from igen_lerobot.core.task import OBS_ENV_STATE

    env = block_grasp(eef_pos_noise=0.002, object_rot_noise_deg=1.0).make_task_env()
    hand_only = block_grasp(eef_pos_noise=0.002).make_task_env()
    env.reset(2)
    hand_only.reset(2)
    angles, position_errors = [], []
    for _ in range(100):
        for e in (env, hand_only):
            e.step(np.array([0.0, 0.0, 0.0, -1.0]))
        observed, plain = env.observe(), hand_only.observe()
        # the hand's noise is drawn from its own stream: the same with or without the objects' noise
        np.testing.assert_array_equal(observed[OBS_STATE], plain[OBS_STATE])
        cube = observed[OBS_ENV_STATE][:7]
        truth = env.believed_object_poses()["cube"]
        position_errors.append(cube[:3] - truth[:3, 3])
        error = Rotation.from_quat(cube[3:7]) * Rotation.from_matrix(truth[:3, :3]).inv()
        angles.append(error.as_rotvec())
    np.testing.assert_allclose(position_errors, 0.0, atol=1e-6)  # orientation only (float32 observations)
    std_deg = float(np.degrees(np.std(angles)))
    assert 0.75 < std_deg < 1.25, std_deg  # 300 samples: the std within 25% of 1 deg per axis
    assert env.randomization.describe()["object_rot_noise_deg"] == 1.0
    assert "object_rot_noise_deg" not in hand_only.randomization.describe()


@pytest.mark.parametrize(
    "randomize, message",
    [
        ({"kp_scale": (1.5, 0.5)}, "env.randomize.kp_scale"),
        ({"kp_scale": (0.0, 1.0)}, "env.randomize.kp_scale"),
        ({"latency": (0.0, 0.05)}, "env.randomize.latency"),
        ({"hand_tilt_deg": 30.0}, "env.randomize.hand_tilt_deg"),
        ({"eef_pos_noise": -1.0}, "env.randomize.eef_pos_noise"),
        ({"object_rot_noise_deg": -1.0}, "env.randomize.object_rot_noise_deg"),
        ({"object_rot_noise_deg": 20.0}, "env.randomize.object_rot_noise_deg"),
    ],
)
def test_bad_ranges_are_refused_by_their_flag(randomize, message):
    with pytest.raises(ConfigError, match=message):
        block_grasp(**randomize)


def test_a_task_that_commands_orientation_refuses_a_hand_tilt():
    from igen_lerobot.core.env_config import task_config_class

    with pytest.raises(ConfigError, match="hand_tilt_deg applies to position-only tasks"):
        task_config_class("nut_insertion")(randomize=ArmRandomization(hand_tilt_deg=2.0))


def test_igen_collect_records_the_randomisation_and_the_card_says_it(tmp_path):
    from igen_lerobot.collection.collect import collect
    from igen_lerobot.collection.config_collect import CollectConfig
    from igen_lerobot.datasets.card import card_fields
    from igen_lerobot.datasets.reader import load_episodes

    args = [
        "--env.type=block_grasp",
        "--mode=demos",
        "--num_episodes=2",
        "--seed=3",
        "--env.randomize.kp_scale=[0.6,1.4]",
        "--env.randomize.latency=[0,0.03]",
        "--env.randomize.object_rot_noise_deg=1",
        f"--dataset.root={tmp_path / 'demos'}",
        "--dataset.repo_id=local/randomised",
    ]
    collect(draccus.parse(CollectConfig, args=args))
    meta = json.loads((tmp_path / "demos" / "meta" / "igen.json").read_text())
    assert meta["origin"]["randomization"]["kp_scale"] == [0.6, 1.4]
    assert meta["origin"]["randomization"]["latency_s"] == [0.0, 0.03]
    assert meta["env"]["randomize"]["latency"] == [0.0, 0.03]  # the full config, as with every collect
    spec = block_grasp().task_spec
    episodes = load_episodes(tmp_path / "demos", spec)
    assert len(episodes) == 2 and all(ep.success for ep in episodes)
    info = json.loads((tmp_path / "demos" / "meta" / "info.json").read_text())
    body = card_fields(tmp_path / "demos", spec, info, meta)["dataset_description"]
    said = "randomised per episode from its seed: controller stiffness x[0.6, 1.4], action latency [0.0, 0.03] s"
    assert said in body and "object-orientation observation noise 1.0 deg (std per axis)" in body
    plain = {**meta, "origin": {k: v for k, v in meta["origin"].items() if k != "randomization"}}
    unrandomised = card_fields(tmp_path / "demos", spec, info, plain)["dataset_description"]
    assert "same in every episode (no dynamics randomisation)" in unrandomised
