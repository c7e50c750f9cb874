"""The generator on the numpy-only fake task: two subtasks, objects at random yaws, exact kinematics.

Because the fake hand reaches every goal exactly, the generated episodes can be checked to 1e-6:
a transformed segment keeps the hand's pose relative to its object (rotation included), MimicGen
walks both subtasks, IntervenGen replays a recovery into the block's true frame after the
policy's mistake, and nothing idles between subtasks.
"""

import numpy as np
import pytest
from fake_task import FakeOperator, FakePickPlaceEnv, FakePolicy

from igen_lerobot.collection.record import record_demo, record_intervention
from igen_lerobot.core.error_models import NoNoise
from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.core.geometry import make_pose, pose_inv, rot_z, rotation_angle
from igen_lerobot.core.recorder import EpisodeRecorder
from igen_lerobot.core.task import FrameSource
from igen_lerobot.generation.intervengen import IntervenGenConfig, MistakeSource, generate_intervention
from igen_lerobot.generation.mimicgen import MimicGenConfig, generate_demo
from igen_lerobot.generation.replay import ReplayConfig, replay_segment
from igen_lerobot.generation.sources import SegmentRole, SourceSegment, parse_demos, parse_interventions


@pytest.fixture(scope="module")
def clean_env():
    return FakePickPlaceEnv(NoNoise())


@pytest.fixture(scope="module")
def demos(clean_env):
    episodes = [record_demo(clean_env, FakeOperator(), seed, 200) for seed in range(3)]
    assert all(ep.success for ep in episodes)
    return parse_demos(episodes, clean_env.spec, clean_env.target_pose_from_action, clean_env.gripper_command)


def _grasp_frame(episode):
    return int(np.flatnonzero(episode.subtask == 1)[0])


def _hand_in_block_frame(spec, episode, frame):
    T_eef = spec.eef_poses(episode.state[frame])
    T_block = spec.object_poses(episode.true_object_pose[frame], "block")
    return pose_inv(T_block) @ T_eef


def test_mimicgen_walks_both_subtasks_and_keeps_each_relative_pose_with_rotation(clean_env, demos):
    spec = clean_env.spec
    assert {(s.role, s.subtask) for s in demos.segments} == {(SegmentRole.SUBTASK, 0), (SegmentRole.SUBTASK, 1)}
    cfg = MimicGenConfig()
    kept = [generate_demo(clean_env, demos, cfg, 100 + i, 300) for i in range(10)]
    assert sum(a.kept for a in kept) == 10
    yaws = set()
    for attempt in kept:
        ep = attempt.episode
        assert ep.success and set(np.unique(ep.subtask)) == {0, 1}
        grasp = _grasp_frame(ep)
        source = demos.select(SegmentRole.SUBTASK, 0)[ep.extra["sources"][0]]
        # the hand met the block exactly as in the source segment it replays, whatever the block's yaw
        relative = _hand_in_block_frame(spec, ep, grasp)
        expected = pose_inv(source.T_world_obj) @ source.targets[-1]
        np.testing.assert_allclose(relative, expected, atol=1e-5)
        yaws.add(round(float(np.arctan2(*ep.true_object_pose[0, [5, 6]])), 2))
        # no idling between subtasks: once grasped, the next frame bridges into the place segment
        assert ep.source[grasp] == FrameSource.INTERPOLATION
    assert len(yaws) == 10  # every scene turned the block differently


def test_intervengen_replays_a_recovery_into_the_blocks_true_frame_after_the_policys_mistake():
    env = FakePickPlaceEnv()
    sources = [record_intervention(env, FakePolicy(), FakeOperator(), 50 + s, 200) for s in range(4)]
    assert all(ep.success and ep.is_intervention.any() for ep in sources)
    library = parse_interventions(sources, env.spec, env.target_pose_from_action, env.gripper_command)
    assert library.select(SegmentRole.RECOVERY, 0) and library.select(SegmentRole.MISTAKE, 0)
    cfg = IntervenGenConfig()
    attempts = [generate_intervention(env, FakePolicy(), library, cfg, 900 + i, 320) for i in range(8)]
    kept = [a.episode for a in attempts if a.kept]
    assert len(kept) >= 7
    for ep in kept:
        revealed = ep.env_state[:, env.spec.env_state_index("revealed")]
        assert revealed[0] == 1.0  # xi[t:]: the episode starts at the mistake state
        assert ep.is_intervention[0] and ep.source[0] == FrameSource.INTERPOLATION
        flagged = np.flatnonzero(ep.is_intervention)
        assert np.all(np.isin(ep.source[flagged], [FrameSource.GENERATED, FrameSource.INTERPOLATION]))
        assert (ep.source == FrameSource.POLICY).any()  # the policy takes back over for the place subtask
        assert ep.success and set(np.unique(ep.subtask)) == {0, 1}
        # the recovery grasped the block with the source recovery's hand-to-block pose
        recovery = library.select(SegmentRole.RECOVERY, 0)
        relative = _hand_in_block_frame(env.spec, ep, _grasp_frame(ep))
        candidates = [pose_inv(s.T_world_obj) @ s.targets[-1] for s in recovery]
        assert min(np.abs(relative - c).max() for c in candidates) < 1e-5
    ablation = [generate_intervention(env, None, library, cfg, 900 + i, 320, MistakeSource.REPLAY) for i in range(8)]
    kept = [a.episode for a in ablation if a.kept]
    assert kept and all(ep.kind == "igen_no_policy" and not (ep.source == FrameSource.POLICY).any() for ep in kept)


def _held_goal_segment(env, goal, gripper_closed: list[bool]) -> SourceSegment:
    """A first-subtask segment that holds one end-effector goal, one frame per recorded gripper command."""
    goals = np.repeat(goal[None], len(gripper_closed), axis=0)
    return SourceSegment(
        episode=0,
        subtask=0,
        role=SegmentRole.SUBTASK,
        object_name="block",
        T_world_obj=env.true_object_poses()["block"],
        eef=goals,
        targets=goals,
        gripper_closed=np.array(gripper_closed),
        corruption=np.zeros(3),
    )


def test_a_bridge_that_turns_further_takes_more_steps(clean_env):
    env = clean_env
    obs = env.reset(0)
    start = env.eef_pose()
    turned = make_pose(start[:3, 3], rot_z(np.pi / 2) @ start[:3, :3])
    segment = _held_goal_segment(env, turned, [False])
    cfg = ReplayConfig(interpolation_steps=5, interpolation_rotation_speed=0.1, hold_steps=0)
    outcome = replay_segment(env, EpisodeRecorder(env), obs, segment, cfg, np.random.default_rng(0), False, 100)
    assert len(outcome.interpolation) == int(np.ceil((np.pi / 2) / 0.1))  # 16: the angle, not the (zero) distance
    assert rotation_angle(env.eef_pose()[:3, :3], turned[:3, :3]) < 1e-9


@pytest.mark.parametrize(
    ("recorded", "frames", "bridge_closed"),
    [
        ([False, True, True, True], 3, True),  # a one-frame open at a policy's first step is not held
        ([True, False, False, False], 3, False),  # nor a one-frame close
        ([False, False, True, True], 3, False),  # a command held from the start is
        ([False, True], 3, False),  # a tie: the first frame's
        ([False, True, True, True], 1, False),  # MimicGen's rule: the first frame's, whatever follows
    ],
)
def test_the_bridge_holds_the_command_the_segment_settles_on(clean_env, recorded, frames, bridge_closed):
    env = clean_env
    obs = env.reset(0)
    start = env.eef_pose()
    away = make_pose(start[:3, 3] + [0.1, 0.0, 0.0], start[:3, :3])
    segment = _held_goal_segment(env, away, recorded)
    cfg = ReplayConfig(interpolation_steps=5, interpolation_speed=0.015, hold_steps=0, bridge_gripper_frames=frames)
    recorder = EpisodeRecorder(env)
    outcome = replay_segment(env, recorder, obs, segment, cfg, np.random.default_rng(0), False, 100)
    bridge = len(outcome.interpolation)
    assert bridge == 7  # 10 cm at 1.5 cm per step
    commands = [env.gripper_command(action) for action in recorder.action]
    assert commands[:bridge] == [bridge_closed] * bridge
    assert commands[bridge:] == recorded  # the segment itself replays every recorded command, blips included


def test_target_noise_perturbs_orientation_as_well_as_position():
    goal = make_pose([0.1, 0.2, 0.3], rot_z(0.4))
    rng = np.random.default_rng(0)
    turned = ReplayConfig(target_rotation_noise=0.05)
    angles = [rotation_angle(turned.perturb(goal, rng)[:3, :3], goal[:3, :3]) for _ in range(2000)]
    assert 0.06 < np.mean(angles) < 0.10  # |N(0, 0.05 I3)| has mean 0.05 * sqrt(8 / pi) = 0.080
    np.testing.assert_array_equal(turned.perturb(goal, rng)[:3, 3], goal[:3, 3])
    moved = ReplayConfig(target_noise=0.01).perturb(goal, rng)
    np.testing.assert_array_equal(moved[:3, :3], goal[:3, :3])
    assert ReplayConfig().perturb(goal, rng) is goal


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("target_noise", -0.1),
        ("target_rotation_noise", -1.0),
        ("hold_steps", -1),
        ("bridge_gripper_frames", 0),
        ("interpolation_steps", 0),
        ("interpolation_speed", 0.0),
        ("interpolation_rotation_speed", 0.0),
    ],
)
def test_every_replay_setting_is_checked(field, value):
    with pytest.raises(ConfigError, match=f"replay.{field}"):
        ReplayConfig(**{field: value})
