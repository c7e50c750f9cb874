"""Corruption samples obey their bounds; seeded generators reproduce them exactly."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from igen_lerobot.core.error_models import BoxNoise, NoNoise, RadialNoise
from igen_lerobot.core.exceptions import ConfigError

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
