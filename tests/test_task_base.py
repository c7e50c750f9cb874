"""The Panda task base: the region placer (no simulator needed).

Exact comparisons where the same generator state must give the same numbers; region bounds to 1e-12 m.
"""

import numpy as np
import pytest

from igen_lerobot.core.exceptions import ConfigError
from lerobot_env_igen.placement import RegionPlacer, UniformRegion


class RecordingScene:
    def __init__(self):
        self.calls = []

    def set_pose(self, name, pos):
        self.calls.append((name, tuple(float(v) for v in pos)))


@pytest.mark.parametrize("seed", [0, 1, 12345])
def test_the_same_generator_state_gives_the_same_placement(seed):
    region = UniformRegion((0.2, 0.3), center=(0.05, -0.02))
    a, b = RecordingScene(), RecordingScene()
    xy_a = RegionPlacer("cube", region, z=0.825).place(a, np.random.default_rng(seed))
    xy_b = RegionPlacer("cube", region, z=0.825).place(b, np.random.default_rng(seed))
    np.testing.assert_array_equal(xy_a, xy_b)
    assert a.calls == b.calls == [("cube", (xy_a[0], xy_a[1], 0.825))]


def test_a_placement_takes_two_uniform_draws_from_the_generator_it_is_handed():
    # what comes after the placement in a reset (the pose error) sees the generator as before the refactor
    region = UniformRegion((0.1, 0.1))
    rng, reference = np.random.default_rng(7), np.random.default_rng(7)
    xy = region.sample(rng)
    np.testing.assert_array_equal(xy, reference.uniform(-0.5, 0.5, size=2) * np.array([0.1, 0.1]))
    assert rng.random() == reference.random()


def test_placements_stay_inside_the_region_and_cover_it():
    region = UniformRegion((0.2, 0.3), center=(0.1, -0.05))
    rng = np.random.default_rng(3)
    points = np.array([region.sample(rng) for _ in range(2000)])
    assert all(region.contains(p) for p in points)
    assert np.all(np.abs(points - [0.1, -0.05]) <= [0.1 + 1e-12, 0.15 + 1e-12])
    assert np.ptp(points[:, 0]) > 0.19 and np.ptp(points[:, 1]) > 0.29  # uses the whole region
    assert not region.contains([0.1, 0.11]) and not region.contains([0.21, -0.05])
    # a zero-sized region is a fixed spot
    np.testing.assert_array_equal(UniformRegion((0.0, 0.0), center=(0.3, 0.4)).sample(rng), [0.3, 0.4])


@pytest.mark.parametrize("extents", [(-0.1, 0.1), (0.1,), (0.1, float("nan"))])
def test_a_bad_region_is_refused_by_the_field_it_came_from(extents):
    with pytest.raises(ConfigError, match=r"env\.peg_region must be non-negative \(x, y\) extents"):
        UniformRegion(extents, flag="env.peg_region")


def test_a_task_config_refuses_a_bad_region_when_it_is_made():
    from lerobot_env_igen.block_grasp.config import BlockGraspEnvConfig
    from lerobot_env_igen.nut_insertion.config import NutInsertionEnvConfig

    with pytest.raises(ConfigError, match=r"env\.cube_region"):
        BlockGraspEnvConfig(cube_region=(0.2, -0.3))
    with pytest.raises(ConfigError, match=r"env\.peg_region"):
        NutInsertionEnvConfig(peg_region=(-0.1, 0.1))
    with pytest.raises(ConfigError, match=r"env\.max_rotation"):
        NutInsertionEnvConfig(max_rotation=0.0)
