"""2-Piece Assembly on real robosuite/MuJoCo physics: the in-hand start, the receptacle's region and
error, the clearance (seated vs on the rim), what counts as success, the direction reveal, and the
scripted operator's recovery under the paper's error.

Tolerances: positions 1 mm unless stated (physics settles the held piece by a fraction of that).
"""

import dataclasses

import numpy as np
import pytest
from in_hand_checks import (
    assert_placed_over_the_region_without_recompiling,
    assert_the_operator_recovers,
    blind_insertion,
)

from igen_lerobot.core.belief import Reveal
from igen_lerobot.core.error_models import BoxNoise, NoNoise
from igen_lerobot.core.geometry import make_pose
from igen_lerobot.core.task import OBS_ENV_STATE


@pytest.fixture(scope="module")
def config():
    from lerobot_env_igen.two_piece_assembly.config import TwoPieceAssemblyEnvConfig

    return TwoPieceAssemblyEnvConfig()


@pytest.fixture(scope="module")
def env(config):
    env = config.make_task_env()
    yield env
    env.close()


def test_the_piece_starts_in_the_hand_above_the_receptacle_region(env):
    from lerobot_env_igen.two_piece_assembly.spec import RECEPTACLE_SIZE, SLAB_HALF, TABLE_TOP_Z

    centres = []
    for seed in range(30):
        env.reset(seed)
        poses = env.true_object_poses()
        piece, receptacle = poses["piece"], poses["receptacle"]
        centres.append(receptacle[:2, 3])
        assert env.parts_in_contact("gripper", "piece")  # held by the fingers ...
        assert 0.019 < env.gripper_width() < 0.022  # ... closed on the 2 cm ridge, not on air
        assert piece[2, 3] - SLAB_HALF[2] - (TABLE_TOP_Z + RECEPTACLE_SIZE[2]) >= 0.05  # 5 cm or more above the rim
        np.testing.assert_allclose(piece[:3, :3], receptacle[:3, :3], atol=0.02)  # yaw aligned, level
        np.testing.assert_allclose(receptacle[:3, :3], np.eye(3), atol=1e-12)
        np.testing.assert_allclose(receptacle[2, 3], TABLE_TOP_Z + RECEPTACLE_SIZE[2] / 2, atol=1e-12)
    assert_placed_over_the_region_without_recompiling(env, "receptacle", np.array(centres))


def test_the_receptacle_error_is_the_papers(env):
    samples = np.array([env.reset(seed) is not None and env.corruption for seed in range(200)])
    assert np.all(np.abs(samples) <= 0.04 + 1e-12)
    assert np.all(np.max(np.abs(samples), axis=1) >= 0.01 - 1e-12)
    assert np.all(np.ptp(samples, axis=0) > 0.06)  # every axis, both signs


def _blind_insertion(config, offset_x: float):
    """The scripted policy believing the receptacle ``offset_x`` [m] off along x, never told better."""
    return blind_insertion(config, BoxNoise(min_abs=(0.0, 0.0, 0.0)), (-offset_x, 0.0, 0.0))


def test_the_piece_goes_in_up_to_6_mm_off_and_jams_on_the_rim_beyond(config):
    """The clearance is 6 mm per side (benchmarks/two_piece_clearance.py measures more offsets)."""
    from lerobot_env_igen.two_piece_assembly.spec import FLOOR_Z, SEATED_XY, SLAB_HALF

    env, success = _blind_insertion(config, 0.006)
    assert success and env.seated() and env.released()
    env.close()
    env, success = _blind_insertion(config, 0.01)
    piece, receptacle = env.true_object_poses()["piece"][:3, 3], env.true_object_poses()["receptacle"][:3, 3]
    # the policy let go, and the piece's centre is within 1 cm of the receptacle's (an xy-only test passes) ...
    assert env.released() and np.linalg.norm(piece[:2] - receptacle[:2]) < SEATED_XY
    # ... but it is jammed on the rim, tilted, its bottom well above the floor: not a success
    assert piece[2] - SLAB_HALF[2] - FLOOR_Z > 0.008
    assert not success and not env.seated() and not env.is_success()
    env.close()


def test_success_needs_the_piece_seated_and_released(config):
    import mujoco

    from lerobot_env_igen.two_piece_assembly.spec import FLOOR_Z, RECEPTACLE_SIZE, SLAB_HALF, TABLE_TOP_Z

    env = dataclasses.replace(config, corruption=NoNoise()).make_task_env()
    env.reset(11)
    receptacle = env.true_object_poses()["receptacle"][:3, 3]
    # a piece centred over the receptacle, level, its bottom at the rim's height: not seated
    env.set_free_pose("piece", np.array([*receptacle[:2], TABLE_TOP_Z + RECEPTACLE_SIZE[2] + SLAB_HALF[2]]))
    mujoco.mj_forward(env.model, env.data)
    assert not env.seated() and not env.is_success()
    # held down at the floor: seated, but not released
    env.reset(11)
    hand = env.eef_pose()
    piece = env.true_object_poses()["piece"][:3, 3]
    over = hand[:3, 3] + np.array([*(receptacle[:2] - piece[:2]), 0.0])
    for _ in range(30):
        env.step(env.action_towards(make_pose(over, hand[:3, :3]), True))
    for _ in range(40):
        down = env.eef_pose()[:3, 3] + np.array([0.0, 0.0, -0.02])
        info = env.step(env.action_towards(make_pose(down, hand[:3, :3]), True))
    assert env.seated() and not env.released() and not info.success
    for _ in range(10):  # let go
        info = env.step(env.action_towards(env.eef_pose(), False))
        if info.success:
            break
    assert info.success and env.seated() and env.released()
    assert env.true_object_poses()["piece"][2, 3] - SLAB_HALF[2] - FLOOR_Z <= 0.005
    env.close()


@pytest.mark.parametrize("reveal", [Reveal.FULL, Reveal.DIRECTION])
def test_the_scripted_operator_recovers_from_the_papers_error(config, reveal):
    """Human-gated episodes: the scripted policy lands the piece off the receptacle; the operator takes
    over at that contact, lifts the piece, moves it over the true receptacle and puts it in."""
    from lerobot_env_igen.two_piece_assembly.spec import RECEPTACLE_SIZE, SLAB_HALF, TABLE_TOP_Z

    rim = TABLE_TOP_Z + RECEPTACLE_SIZE[2]
    assert_the_operator_recovers(dataclasses.replace(config, reveal=reveal), "piece", rim + SLAB_HALF[2] + 0.015, 8)


def test_direction_reveal_gives_the_unit_vector_to_the_true_receptacle(config):
    cfg = dataclasses.replace(config, reveal=Reveal.DIRECTION)
    env, policy = cfg.make_task_env(), cfg.make_scripted_policy()
    spec = cfg.task_spec
    hint = [spec.env_state_index(f"receptacle.dir.{a}") for a in "xyz"]
    revealed = 0
    for seed in range(5):
        obs = env.reset(seed)
        for _ in range(80):
            assert not obs[OBS_ENV_STATE][hint].any()
            info = env.step(policy.act(obs))
            obs = env.observe()
            if info.revealed:
                break
        if not info.revealed:
            continue
        revealed += 1
        truth = env.true_object_poses()["receptacle"][:3, 3]
        believed = env.believed_object_poses()["receptacle"][:3, 3]
        np.testing.assert_allclose(believed, truth + env.corruption, atol=1e-9)  # the belief stays wrong
        expected = np.array([*(truth - believed)[:2], 0.0])
        np.testing.assert_allclose(obs[OBS_ENV_STATE][hint], expected / np.linalg.norm(expected), atol=1e-6)
    assert revealed >= 4
    env.close()
