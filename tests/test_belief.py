"""The core belief model: every reveal mode the paper uses, on one object, as properties.

Tolerance 1e-12 m (pure arithmetic).
"""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from igen_lerobot.core.belief import ObjectBelief, Reveal
from igen_lerobot.core.error_models import BoxNoise, YawFlip
from igen_lerobot.core.geometry import make_pose
from igen_lerobot.core.observation import environment_state
from igen_lerobot.core.task import OBS_ENV_STATE

seeds = st.integers(0, 2**32 - 1)
MODEL = BoxNoise(half_extent=(0.04, 0.04, 0.04), min_abs=(0.02, 0.02, 0.02))


def _scene(seed):
    rng = np.random.default_rng(seed)
    truth = make_pose(rng.uniform(-0.3, 0.3, 3), Rotation.from_euler("z", rng.uniform(-3, 3)).as_matrix())
    return rng, truth, MODEL.sample(rng)


@given(seeds, st.sampled_from(list(Reveal)))
def test_before_the_contact_every_mode_believes_the_error_model(seed, reveal):
    _, truth, sample = _scene(seed)
    belief = ObjectBelief(MODEL, sample, reveal)
    assert not belief.update(False, None, truth)  # no contact: nothing happens
    np.testing.assert_allclose(belief.believed_pose(truth), MODEL.apply(truth, sample), atol=1e-12)
    assert not belief.revealed and not belief.contact
    np.testing.assert_array_equal(belief.hint(), np.zeros(3) if reveal is Reveal.DIRECTION else np.zeros(0))


@given(seeds)
def test_full_reveals_the_truth_from_the_first_contact_on_and_only_once(seed):
    rng, truth, sample = _scene(seed)
    belief = ObjectBelief(MODEL, sample, Reveal.FULL)
    assert belief.update(True, rng.uniform(-1, 1, 3), truth)  # the revealing contact: the mistake
    assert not belief.update(True, None, truth)  # later contacts reveal nothing new
    moved = make_pose(truth[:3, 3] + 0.05, truth[:3, :3])
    np.testing.assert_allclose(belief.believed_pose(moved), moved, atol=1e-12)  # it tracks the truth
    belief.update(False, None, moved)
    assert belief.revealed and not belief.contact  # revealed is latched, contact is per step


@given(seeds)
def test_none_never_reveals(seed):
    _, truth, sample = _scene(seed)
    belief = ObjectBelief(MODEL, sample, Reveal.NONE)
    assert belief.update(True, truth[:3, 3], truth)  # the contact is still the mistake signal ...
    np.testing.assert_allclose(belief.believed_pose(truth), MODEL.apply(truth, sample), atol=1e-12)  # ... no news


@given(seeds)
def test_contact_position_replaces_the_position_with_where_the_contact_was(seed):
    rng, truth, sample = _scene(seed)
    belief = ObjectBelief(MODEL, sample, Reveal.CONTACT_POSITION)
    where = truth[:3, 3] + rng.uniform(-0.02, 0.02, 3)
    belief.update(True, where, truth)
    believed = belief.believed_pose(truth)
    np.testing.assert_allclose(believed[:3, 3], where, atol=1e-12)
    np.testing.assert_allclose(believed[:3, :3], truth[:3, :3], atol=1e-12)  # position errors keep the rotation
    belief.update(True, where + 1.0, truth)  # a later contact does not move it
    np.testing.assert_allclose(belief.believed_pose(truth)[:3, 3], where, atol=1e-12)


@given(seeds)
def test_direction_observes_a_unit_vector_from_the_belief_to_the_truth(seed):
    _, truth, sample = _scene(seed)
    belief = ObjectBelief(MODEL, sample, Reveal.DIRECTION)
    belief.update(True, None, truth)
    hint = belief.hint()
    assert hint.shape == (3,) and hint[2] == 0.0
    expected = -sample[:2] / np.linalg.norm(sample[:2])  # believed = truth + sample
    np.testing.assert_allclose(hint[:2], expected, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(hint), 1.0, atol=1e-12)
    np.testing.assert_allclose(belief.believed_pose(truth), MODEL.apply(truth, sample), atol=1e-12)  # still wrong


def test_a_geometry_error_is_revealed_like_any_other():
    truth = make_pose([0.0, 0.1, 0.82], Rotation.from_euler("z", 0.7).as_matrix())
    belief = ObjectBelief(YawFlip(), np.array([1.0]), Reveal.FULL)
    assert not np.allclose(belief.believed_pose(truth), truth)
    belief.update(True, None, truth)
    np.testing.assert_allclose(belief.believed_pose(truth), truth, atol=1e-12)


def test_the_observation_carries_the_signals_and_the_hint_in_the_declared_layout():
    from lerobot_env_igen.block_grasp.spec import SPEC

    truth = make_pose([0.05, -0.02, 0.825])
    sample = np.array([0.005, 0.03, 0.0])
    spec = SPEC.with_reveal(Reveal.DIRECTION)
    belief = ObjectBelief(BoxNoise(), sample, Reveal.DIRECTION)
    before = environment_state(spec, {"cube": belief.believed_pose(truth)}, belief)
    belief.update(True, None, truth)
    after = environment_state(spec, {"cube": belief.believed_pose(truth)}, belief)
    names = spec.env_state_names
    assert names[-5:] == ("contact", "revealed", "cube.dir.x", "cube.dir.y", "cube.dir.z") and len(after) == len(names)
    assert before[names.index("revealed")] == 0 and after[names.index("revealed")] == 1
    np.testing.assert_allclose(after[-3:-1], -sample[:2] / np.linalg.norm(sample[:2]), atol=1e-6)
    np.testing.assert_allclose(before[-3:], 0.0)
    assert OBS_ENV_STATE == "observation.environment_state"


def test_a_sample_that_does_not_fit_the_model_is_refused():
    from igen_lerobot.core.exceptions import ConfigError

    with pytest.raises(ConfigError, match="3 values"):
        ObjectBelief(BoxNoise(), np.zeros(1), Reveal.FULL)
