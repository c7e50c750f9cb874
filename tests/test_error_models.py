"""Error models: samples obey their bounds, seeded generators reproduce them, and apply() makes the belief."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from igen_lerobot.core.error_models import BoxNoise, NoNoise, RadialNoise, YawFlip
from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.core.geometry import make_pose, rotation_angle

seeds = st.integers(0, 2**32 - 1)
BLOCK_GRASP = BoxNoise(half_extent=(0.01, 0.07, 0.0), min_abs=(0.0, 0.025, 0.0), require="all")


@given(seeds)
def test_block_grasp_noise_bounds(seed):
    offset = BLOCK_GRASP.sample(np.random.default_rng(seed))
    assert abs(offset[0]) <= 0.01
    assert 0.025 <= abs(offset[1]) <= 0.07
    assert offset[2] == 0.0
    assert BLOCK_GRASP.contains(offset)


@given(seeds)
def test_any_axis_minimum(seed):
    noise = BoxNoise(half_extent=(0.04, 0.04, 0.04), min_abs=(0.02, 0.02, 0.02), require="any")
    offset = noise.sample(np.random.default_rng(seed))
    assert np.all(np.abs(offset) <= 0.04)
    assert np.max(np.abs(offset)) >= 0.02
    assert noise.contains(offset)


@given(seeds)
def test_radial_noise_bounds(seed):
    noise = RadialNoise(r_min=0.02, r_max=0.04)
    offset = noise.sample(np.random.default_rng(seed))
    assert 0.02 <= np.linalg.norm(offset[:2]) <= 0.04 + 1e-12
    assert offset[2] == 0.0
    assert noise.contains(offset)


def test_contains_rejects_out_of_bounds_values():
    assert not BLOCK_GRASP.contains(np.array([0.0, 0.01, 0.0]))  # |y| below the minimum
    assert not BLOCK_GRASP.contains(np.array([0.02, 0.03, 0.0]))  # x beyond the extent
    assert not NoNoise().contains(np.array([0.0, 1e-3, 0.0]))


def test_same_seed_same_sample_and_distribution_covers_both_signs():
    a = [BLOCK_GRASP.sample(np.random.default_rng(s)) for s in range(200)]
    b = [BLOCK_GRASP.sample(np.random.default_rng(s)) for s in range(200)]
    np.testing.assert_array_equal(a, b)
    ys = np.array(a)[:, 1]
    assert (ys > 0).sum() > 60 and (ys < 0).sum() > 60


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"half_extent": (0.01, 0.02, 0.0), "min_abs": (0.0, 0.03, 0.0)}, "min_abs"),
        ({"half_extent": (0.01, 0.02), "min_abs": (0.0, 0.0, 0.0)}, "half_extent"),
        ({"require": "most"}, "require"),
    ],
)
def test_bad_box_config_names_the_field(kwargs, field):
    with pytest.raises(ConfigError, match=field):
        BoxNoise(**kwargs)


def test_bad_radial_config():
    with pytest.raises(ConfigError, match="r_min"):
        RadialNoise(r_min=0.05, r_max=0.01)


@given(seeds)
def test_yaw_flip_turns_the_believed_pose_half_a_turn_about_its_own_z(seed):
    rng = np.random.default_rng(seed)
    flip = YawFlip()
    sample = flip.sample(rng)
    assert flip.contains(sample) and sample.shape == (1,)
    truth = make_pose(rng.uniform(-1, 1, 3), Rotation.random(random_state=rng).as_matrix())
    believed = flip.apply(truth, sample)
    np.testing.assert_allclose(believed[:3, 3], truth[:3, 3], atol=1e-12)  # same position
    expected_angle = np.pi if sample[0] == 1.0 else 0.0
    assert abs(rotation_angle(believed[:3, :3], truth[:3, :3]) - expected_angle) < 1e-6
    np.testing.assert_allclose(believed[:3, 2], truth[:3, 2], atol=1e-9)  # about the object's own z axis


def test_yaw_flip_is_a_coin_and_respects_its_probability():
    flips = np.array([YawFlip().sample(np.random.default_rng(s))[0] for s in range(2000)])
    assert set(np.unique(flips)) == {0.0, 1.0} and 0.45 < flips.mean() < 0.55
    never = YawFlip(probability=0.0)
    assert not never.contains(np.array([1.0])) and never.contains(np.array([0.0]))
    with pytest.raises(ConfigError, match="probability"):
        YawFlip(probability=1.5)


def test_position_models_move_the_position_only_and_none_changes_nothing():
    truth = make_pose([0.1, -0.2, 0.8], Rotation.from_euler("z", 0.3).as_matrix())
    offset = np.array([0.01, -0.03, 0.0])
    for model in (BLOCK_GRASP, RadialNoise(), BoxNoise()):
        believed = model.apply(truth, offset)
        np.testing.assert_allclose(believed[:3, 3], truth[:3, 3] + offset)
        np.testing.assert_array_equal(believed[:3, :3], truth[:3, :3])
        assert model.names == ("dx", "dy", "dz")
    np.testing.assert_array_equal(NoNoise().apply(truth, np.zeros(3)), truth)


def test_a_sample_of_the_wrong_size_names_the_field_and_the_model():
    with pytest.raises(ConfigError, match=r"corruption override must hold 3 values .*'box'"):
        BoxNoise().checked(np.zeros(2), "corruption override")
    assert NoNoise(layout=("flip",)).sample(np.random.default_rng(0)).shape == (1,)
