"""The Panda task base: the region placer and the scripted agents' takeover rule (no simulator needed).

Exact comparisons where the same generator state must give the same numbers; region bounds to 1e-12 m.
"""

import numpy as np
import pytest

from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.core.geometry import make_pose
from lerobot_env_igen.panda_spec import GRIPPER
from lerobot_env_igen.placement import RegionPlacer, UniformRegion
from lerobot_env_igen.scripted import OffAxisTakeover, ScriptedOperator, WaypointRule


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


class StubEnv:
    """The true poses and signals a takeover rule reads."""

    def __init__(self, eef, objects, width=0.08, contact=False):
        self._eef, self._objects, self._width, self.contact = eef, objects, width, contact

    def eef_pose(self):
        return make_pose(self._eef)

    def true_object_poses(self):
        return {name: make_pose(pos) for name, pos in self._objects.items()}

    def gripper_width(self):
        return self._width


HELD_ON_PEG = OffAxisTakeover(
    moving="nut", target="peg", mistake_xy=0.006, target_top=0.065, low_margin=-0.01, moving_bottom=0.01
)
GRASP = OffAxisTakeover(
    moving=GRIPPER, target="cube", mistake_xy=0.01, target_top=0.025, low_margin=0.01, closing_width=0.078
)
PEG = np.array([0.0, 0.0, 0.865])  # top at 0.93


@pytest.mark.parametrize(
    ("nut", "contact", "takes_over"),
    [
        ((0.02, 0.0, 0.95), True, True),  # landed on the peg top, off the axis: the revealing contact
        ((0.02, 0.0, 0.95), False, False),  # off the axis but above the top, no contact: not yet
        ((0.004, 0.0, 0.95), True, False),  # touching within the clearance: it slides on
        ((0.05, 0.0, 0.935), False, False),  # bottom 0.925: just under the top (0.93), above the low line (0.92)
        ((0.05, 0.0, 0.91), False, True),  # bottom 0.90: passed beside the peg (low), no contact needed
        ((0.0, 0.0, 0.85), False, False),  # down the peg on its axis: fine
    ],
)
def test_the_off_axis_takeover_for_a_held_part(nut, contact, takes_over):
    env = StubEnv(eef=(0.0, 0.0, 1.0), objects={"nut": np.array(nut), "peg": PEG}, contact=contact)
    assert bool(HELD_ON_PEG.judges_mistake(env)) is takes_over


def test_the_off_axis_takeover_for_the_hand_counts_closing_only_when_asked():
    cube = {"cube": np.array([0.0, 0.0, 0.825])}
    high_off_axis = (0.03, 0.0, 0.95)
    assert not GRASP.judges_mistake(StubEnv(high_off_axis, cube, width=0.08))
    assert GRASP.judges_mistake(StubEnv(high_off_axis, cube, width=0.05))  # closing beside the cube
    assert not GRASP.judges_mistake(StubEnv((0.005, 0.0, 0.95), cube, width=0.05))  # closing over it
    no_closing = OffAxisTakeover(moving=GRIPPER, target="cube", mistake_xy=0.01, target_top=0.025, low_margin=0.01)
    assert not no_closing.judges_mistake(StubEnv(high_off_axis, cube, width=0.05))
    assert GRASP.judges_mistake(StubEnv((0.03, 0.0, 0.855), cube))  # fingertips down beside it (a miss)


class StandStill(WaypointRule):
    def act(self, T_world_eef, width, T_world_obj, actions):
        return np.zeros(4)


class Always:
    def judges_mistake(self, env):
        return True


class Never:
    def judges_mistake(self, env):
        return False


def test_the_scripted_operator_takes_over_when_its_takeover_rule_says_so():
    env = StubEnv((0.0, 0.0, 1.0), {})
    eager, patient = ScriptedOperator(StandStill(), Always(), 100), ScriptedOperator(StandStill(), Never(), 3)
    for operator in (eager, patient):
        operator.reset(env)
    assert eager.wants_control(env, in_control=False)
    decisions = [patient.wants_control(env, in_control=False) for _ in range(5)]
    assert decisions == [False, False, False, True, True]  # only its patience runs out
    assert patient.wants_control(env, in_control=True)  # once in control it keeps it


def test_the_shipped_tasks_build_their_takeover_from_their_geometry():
    from lerobot_env_igen.block_grasp.scripted import ScriptedGraspOperator
    from lerobot_env_igen.nut_insertion.config import NutInsertionEnvConfig

    nut = NutInsertionEnvConfig().make_scripted_operator()
    assert nut.takeover == HELD_ON_PEG and nut.patience_steps == 150
    grasp = ScriptedGraspOperator()
    assert grasp.takeover == GRASP and grasp.patience_steps == 100
