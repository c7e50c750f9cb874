"""Coffee on real robosuite/MuJoCo physics: the in-hand start, the machine's region and radial error,
the reveal on any machine geom, the clearance (seated vs on the rim), what counts as success, and the
scripted operator's recovery under the paper's error.

Tolerances: positions 1 mm unless stated (physics settles the held pod by a fraction of that).
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
from igen_lerobot.core.error_models import NoNoise, RadialNoise
from igen_lerobot.core.geometry import make_pose


@pytest.fixture(scope="module")
def config():
    from lerobot_env_igen.coffee.config import CoffeeEnvConfig

    return CoffeeEnvConfig()


@pytest.fixture(scope="module")
def env(config):
    env = config.make_task_env()
    yield env
    env.close()


def test_the_pod_starts_in_the_hand_above_the_machine_region(env):
    from lerobot_env_igen.coffee.spec import BODY_TOP_Z, POD_HALF_HEIGHT, TABLE_TOP_Z

    centres = []
    for seed in range(30):
        env.reset(seed)
        poses = env.true_object_poses()
        pod, machine = poses["pod"], poses["machine"]
        centres.append(machine[:2, 3])
        assert env.parts_in_contact("gripper", "pod") and not env.parts_in_contact("pod", "machine")
        assert 0.040 < env.gripper_width() < 0.044  # closed on the 4.3 cm pod, not on air
        assert pod[2, 3] - POD_HALF_HEIGHT - BODY_TOP_Z >= 0.035  # its bottom 3.5 cm or more above the machine
        np.testing.assert_allclose(pod[:3, :3], np.eye(3), atol=0.02)  # upright
        np.testing.assert_allclose(np.linalg.norm(pod[:2, 3] - env.eef_pose()[:2, 3]), 0.0, atol=0.001)
        np.testing.assert_allclose(machine[:3, :3], np.eye(3), atol=1e-12)
        np.testing.assert_allclose(machine[2, 3], TABLE_TOP_Z, atol=1e-12)
    assert_placed_over_the_region_without_recompiling(env, "machine", np.array(centres))


def test_the_machine_error_is_the_papers_radial_2_to_4_cm(env):
    assert env.error_model == RadialNoise(r_min=0.02, r_max=0.04, axes=(0, 1))
    samples = np.array([env.reset(seed) is not None and env.corruption for seed in range(200)])
    radius = np.linalg.norm(samples[:, :2], axis=1)
    assert np.all((radius >= 0.02 - 1e-12) & (radius <= 0.04 + 1e-12)) and not samples[:, 2].any()
    angle = np.arctan2(samples[:, 1], samples[:, 0])
    assert np.histogram(angle, bins=4, range=(-np.pi, np.pi))[0].min() >= 30  # every direction


def test_every_machine_geom_reveals_the_body_and_the_holder_alike(config):
    """A pod erring towards the body lands on the body; one erring sideways lands on the holder's rim:
    both contacts reveal, and the hand touching the machine does not."""
    import mujoco

    env, policy = config.make_task_env(), config.make_scripted_policy()
    names = {
        mujoco.mj_id2name(env.model, mujoco.mjtObj.mjOBJ_GEOM, int(g))
        for g in np.flatnonzero(env.part_masks["machine"])
    }
    assert {"machine_base", "machine_body", "machine_holder0", "machine_holder31"} <= names and len(names) == 34
    for error, part in (((0.03, 0.0), "machine_body"), ((0.0, 0.03), "machine_holder")):
        obs = env.reset(0, corruption=np.array([*error, 0.0]))
        for _ in range(60):
            info = env.step(policy.act(obs))
            obs = env.observe()
            if info.revealed:
                break
        assert info.revealed and info.mistake and set(env.revealing_parts()) == {"pod", "machine"}
        touched = {
            mujoco.mj_id2name(env.model, mujoco.mjtObj.mjOBJ_GEOM, int(g))
            for g in env.last_reveal_contact.geom_pairs[0]
        }
        assert any(name.startswith(part) for name in touched), touched
    env.close()


def _blind_insertion(config, offset_xy):
    """The scripted policy believing the machine ``offset_xy`` [m] off, never told better."""
    return blind_insertion(config, RadialNoise(r_min=0.0, r_max=0.05), (*offset_xy, 0.0))


def test_the_pod_goes_in_up_to_4_mm_off_and_jams_on_the_rim_beyond(config):
    """The taper funnels a pod up to 4 mm off the axis in (benchmarks/coffee_clearance.py measures more)."""
    from lerobot_env_igen.coffee.spec import FLOOR_Z, POD_HALF_HEIGHT, SEATED_XY

    for offset in ((-0.004, 0.0), (0.0, 0.004), (0.004, 0.0)):
        env, success = _blind_insertion(config, offset)
        assert success and env.seated() and env.released(), offset
        env.close()
    env, success = _blind_insertion(config, (-0.006, 0.0))
    # 6 mm off (away from the body) the pod jams on the rim, tilted in the hand, the policy pushing down in vain
    assert not success and not env.released()
    for step in range(30):  # let go and move the hand up
        goal = env.eef_pose()
        goal[2, 3] += 0.01 if step >= 8 else 0.0
        env.step(env.action_towards(goal, False))
    pod, holder = env.true_object_poses()["pod"], env.true_object_poses()["machine"]
    # released, its centre within 5 mm of the holder's axis (an xy-only test passes) ...
    assert env.released() and np.linalg.norm(pod[:2, 3] - holder[:2, 3]) < SEATED_XY
    # ... but resting tilted on the rim, its bottom well above the floor: not a success
    assert pod[2, 3] - POD_HALF_HEIGHT - FLOOR_Z > 0.01 and pod[2, 2] < np.cos(np.radians(15))
    assert not env.seated() and not env.is_success()
    env.close()


def test_the_base_policy_fails_on_the_papers_error_when_never_told(config):
    cfg = dataclasses.replace(config, reveal=Reveal.NONE)
    env, policy = cfg.make_task_env(), cfg.make_scripted_policy()
    for seed in range(4):
        obs = env.reset(seed)
        for _ in range(120):
            info = env.step(policy.act(obs))
            obs = env.observe()
            assert not info.success
        assert env.revealed  # it touched the machine: on the rim or the body, not in the holder
    env.close()


def test_success_needs_the_pod_seated_and_released(config):
    import mujoco

    from lerobot_env_igen.coffee.spec import FLOOR_Z, POD_HALF_HEIGHT, RING_TOP_Z

    env = dataclasses.replace(config, corruption=NoNoise()).make_task_env()
    env.reset(11)
    holder = env.true_object_poses()["machine"][:3, 3]
    # a pod right on the holder's axis, upright, its bottom at the rim's height (xy alone would pass): not seated
    env.set_free_pose("pod", np.array([*holder[:2], RING_TOP_Z + POD_HALF_HEIGHT]))
    mujoco.mj_forward(env.model, env.data)
    assert not env.seated() and not env.is_success()
    # held down at the floor: seated, but not released
    env.reset(11)
    hand = env.eef_pose()
    pod = env.true_object_poses()["pod"][:3, 3]
    over = hand[:3, 3] + np.array([*(holder[:2] - pod[:2]), 0.0])
    for _ in range(20):
        env.step(env.action_towards(make_pose(over, hand[:3, :3]), True))
    down = over - np.array([0.0, 0.0, pod[2] - POD_HALF_HEIGHT - FLOOR_Z + 0.003])  # 3 mm into the floor
    for _ in range(40):
        info = env.step(env.action_towards(make_pose(down, hand[:3, :3]), True))
    assert env.seated() and not env.released() and not info.success
    for _ in range(10):  # let go
        info = env.step(env.action_towards(env.eef_pose(), False))
        if info.success:
            break
    assert info.success and env.seated() and env.released()
    assert env.true_object_poses()["pod"][2, 3] - POD_HALF_HEIGHT - FLOOR_Z <= 0.005
    env.close()


def test_the_scripted_operator_recovers_from_the_papers_error(config):
    """Human-gated episodes: the scripted policy lands the pod on the rim or the body; the operator takes
    over at that contact, lifts the pod, moves it over the true holder and puts it in."""
    from lerobot_env_igen.coffee.spec import POD_HALF_HEIGHT, RING_TOP_Z

    assert_the_operator_recovers(config, "pod", RING_TOP_Z + POD_HALF_HEIGHT + 0.015, 6)
