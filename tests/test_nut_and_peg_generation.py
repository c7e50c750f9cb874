"""Nut-and-Peg generation over its two subtasks, through igen-collect and igen-generate (in this process).

IntervenGen on geometry 2: the scripted base policy acts on the observed pose (the handle on the
wrong side) and closes on air; a source grasp recovery (open, rise, across, regrasp) is moved into
the nut's true frame and replayed flagged; once the nut is held the policy places it, unflagged.
The ablation replays a source mistake and source recoveries; MimicGen replays a grasp segment
relative to the nut, then a place segment relative to the peg. Datasets are read back with
LeRobot's loader. Sources: 2 demonstrations (geometry 1) and 2 interventions (geometry 2).
"""

import numpy as np
import pytest
from test_nut_insertion_cli import ok, run_here

from igen_lerobot.core.episode import EpisodeKind
from igen_lerobot.core.geometry import pos_quat_to_pose
from igen_lerobot.core.task import FrameSource
from igen_lerobot.datasets.reader import dataset_spec, load_episodes

TASK = "--env.type=nut_and_peg"


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    """Sources from igen-collect and one small dataset per generation mode."""
    root = tmp_path_factory.mktemp("nut_and_peg")
    collect = ("igen-collect", TASK, "--num_episodes=2", "--seed=5")
    ok(run_here(*collect, "--env.geometry=1", "--mode=demos", f"--dataset.root={root / 'demos'}"))
    ok(run_here(*collect, "--env.geometry=2", "--mode=interventions", f"--dataset.root={root / 'int'}"))
    for mode, source, geometry, n in (
        ("igen", "int", "2", 1),
        ("igen_no_policy", "int", "2", 1),
        ("mimicgen", "demos", "1", 2),
    ):
        ok(
            run_here(
                "igen-generate",
                f"--mode={mode}",
                TASK,
                f"--env.geometry={geometry}",
                f"--source.root={root / source}",
                f"--num_episodes={n}",
                "--seed=3",
                "--workers=1",
                f"--dataset.root={root / mode}",
            )
        )
    return root


def _runs(flags: np.ndarray) -> list[tuple[bool, int, int]]:
    """(flag, start, end) of each run of equal flags."""
    edges = [0, *(np.flatnonzero(np.diff(flags.astype(int))) + 1).tolist(), len(flags)]
    return [(bool(flags[a]), a, b) for a, b in zip(edges[:-1], edges[1:], strict=True)]


def test_intervengen_recovers_the_missed_grasp_then_the_policy_places(data):
    from lerobot_env_igen.nut_and_peg.scripted import grasp_pose
    from lerobot_env_igen.nut_and_peg.spec import EMPTY_WIDTH, GRIP_X, HELD_WIDTH

    spec = dataset_spec(data / "igen")
    (ep,) = load_episodes(data / "igen", spec)
    assert ep.kind == EpisodeKind.IGEN and ep.success and ep.corruption[0] == 1.0
    width = ep.state[:, spec.state_names.index("gripper.width")]
    eef = spec.eef_poses(ep.state)
    believed = pos_quat_to_pose(ep.env_state[0, :3], ep.env_state[0, 3:7])
    nut = spec.object_poses(ep.true_object_pose, "nut")
    # stored from the policy's mistake on: its fingers closed on air at the grasp point it believed
    assert width[0] < EMPTY_WIDTH
    assert np.linalg.norm(eef[0][:2, 3] - grasp_pose(believed)[:2, 3]) < 0.015
    (recovery, recovery_start, recovery_end), (policy, _, end) = _runs(ep.is_intervention)
    assert recovery and recovery_start == 0 and not policy and end == ep.length  # flagged, then the policy's
    assert (ep.source[:recovery_end] != FrameSource.POLICY).all() and (
        ep.source[recovery_end:] == FrameSource.POLICY
    ).all()
    # the recovery regrasps: opens, goes ~12.4 cm across in the nut's frame, closes on the real handle
    opened = int(np.argmax(width > 0.07))
    assert 0 < opened < recovery_end
    assert HELD_WIDTH[0] <= width[recovery_end] <= HELD_WIDTH[1]
    in_nut = [np.linalg.inv(nut[k]) @ eef[k] for k in (0, recovery_end)]
    assert abs(np.linalg.norm(in_nut[1][:2, 3] - in_nut[0][:2, 3]) - 2 * GRIP_X) < 0.02
    # handed back holding the nut: the place subtask is the policy's, unflagged, to success
    assert (ep.subtask[:recovery_end] == 0).any() and (ep.subtask[recovery_end:] == 1).all()


def test_the_ablation_keeps_an_episode_of_replayed_recoveries(data):
    spec = dataset_spec(data / "igen_no_policy")
    (ep,) = load_episodes(data / "igen_no_policy", spec)
    assert ep.kind == EpisodeKind.IGEN_NO_POLICY and ep.success and ep.is_intervention[0]
    assert not (ep.source == FrameSource.POLICY).any()
    assert set(np.unique(ep.subtask)) == {0, 1}


def test_mimicgen_demonstrations_on_geometry_1_succeed(data):
    spec = dataset_spec(data / "mimicgen")
    episodes = load_episodes(data / "mimicgen", spec)
    assert len(episodes) == 2
    for ep in episodes:
        assert ep.kind == EpisodeKind.MIMICGEN and ep.success and not ep.is_intervention.any()
        assert ep.subtask[0] == 0 and np.all(np.diff(ep.subtask) >= 0) and ep.subtask[-1] == 1  # grasp, then place


def test_the_recording_shows_the_missed_grasp_and_the_regrasp(data, tmp_path):
    """igen-viz of the generated episode, read back with Rerun's reader: flag and subtask plots, events."""
    from test_viz import column, read_rrd

    from lerobot_env_igen.nut_and_peg.spec import EMPTY_WIDTH, HELD_WIDTH

    out = tmp_path / "igen.rrd"
    ok(run_here("igen-viz", f"--dataset.root={data / 'igen'}", f"--output={out}"))
    chunks = read_rrd(out)
    spec = dataset_spec(data / "igen")
    (ep,) = load_episodes(data / "igen", spec)
    root = "/episodes/0"
    flag = np.array(column(chunks[f"{root}/flag"], "Scalars:scalars")).reshape(-1)
    subtask = np.array(column(chunks[f"{root}/subtask"], "Scalars:scalars")).reshape(-1)
    np.testing.assert_array_equal(flag, ep.is_intervention.astype(float))
    np.testing.assert_array_equal(subtask, ep.subtask.astype(float))
    events = [text for row in column(chunks[f"{root}/events"], "TextLog:text") for text in row]
    takeover, subtask_change, hand_back, end = events
    mm = [float(e.split("gripper ")[1].split(" mm")[0]) / 1000 for e in (takeover, subtask_change, hand_back)]
    assert takeover.startswith("takeover") and mm[0] < EMPTY_WIDTH  # the missed grasp: closed on air
    assert subtask_change.startswith("subtask 0 -> 1 (place)")  # the regrasp
    assert hand_back.startswith("hand-back") and HELD_WIDTH[0] <= mm[2] <= HELD_WIDTH[1]  # holding the nut
    assert end == "end: success"


class _FreezesWithTheNutInTheAir:
    """The scripted base policy, except that once it holds the nut lifted off the table it stops there.

    What the table's learned policy does after a regrasp on geometry 2 (``benchmarks/nut_and_peg_ends.py``):
    it holds the nut still in the air off the peg to the end of the episode.
    """

    def __init__(self, config) -> None:
        self.inner, self.actions = config.make_scripted_policy(), config.make_action_space()

    def reset(self) -> None:
        self.inner.reset()

    def act(self, observation):
        from igen_lerobot.core.task import OBS_ENV_STATE, OBS_STATE
        from lerobot_env_igen.nut_and_peg.spec import HELD_WIDTH
        from lerobot_env_igen.square_nut import NUT_HALF_THICKNESS, TABLE_TOP_Z

        state, nut = observation[OBS_STATE], observation[OBS_ENV_STATE]
        holding = HELD_WIDTH[0] <= state[7] <= HELD_WIDTH[1]
        if holding and nut[2] > TABLE_TOP_Z + NUT_HALF_THICKNESS + 0.03:  # the observed nut's centre is exact
            here = pos_quat_to_pose(state[:3], state[3:7])
            return self.actions.action_towards(here, here, True)
        return self.inner.act(observation)


def test_a_place_that_stalls_is_recovered_and_the_episode_kept():
    """IntervenGen on geometry 2 with a policy that freezes holding the nut: the grasp's missed grasp and
    the place's stall each take a flagged source recovery; between them the policy's unflagged place
    frames; the place recovery finishes the task. Without the place's signal the attempt fails."""
    from igen_lerobot.collection.record import record_intervention
    from igen_lerobot.core.seeding import episode_seed
    from igen_lerobot.generation.intervengen import IntervenGenConfig, generate_intervention
    from igen_lerobot.generation.sources import parse_interventions
    from lerobot_env_igen.nut_and_peg.config import NutAndPegEnvConfig
    from lerobot_env_igen.nut_and_peg.env import STALL_STEPS, NutAndPegEnv

    config = NutAndPegEnvConfig(geometry="2")
    env, actions = config.make_task_env(), config.make_action_space()
    scripted, operator = config.make_scripted_policy(), config.make_scripted_operator()
    sources = [
        record_intervention(env, scripted, operator, episode_seed(7, i), config.episode_length) for i in range(2)
    ]
    library = parse_interventions(sources, config.task_spec, actions.target_pose, actions.gripper_closed)
    policy, cfg = _FreezesWithTheNutInTheAir(config), IntervenGenConfig()
    max_steps = config.episode_length + cfg.mistake_budget
    attempt = generate_intervention(env, policy, library, cfg, 3, max_steps)
    assert attempt.kept, attempt.reason
    ep = attempt.episode
    assert ep.kind == EpisodeKind.IGEN and ep.success and len(attempt.details["recoveries"]) == 2
    (grasp_rec, _, grasp_end), (policy_run, _, stall), (place_rec, _, end) = _runs(ep.is_intervention)
    assert grasp_rec and not policy_run and place_rec and end == ep.length
    assert (ep.subtask[:grasp_end] == 0).any() and (ep.subtask[grasp_end:] == 1).all()  # the place from the regrasp on
    assert (ep.source[grasp_end:stall] == FrameSource.POLICY).all() and stall - grasp_end > STALL_STEPS
    assert not (ep.source[stall:] == FrameSource.POLICY).any()  # the source's place to the end
    # the signal off, the same attempt never recovers the place: the budget leaves the place to the policy
    original = NutAndPegEnv._place_stalled
    NutAndPegEnv._place_stalled = lambda self: False
    try:
        assert generate_intervention(env, policy, library, cfg, 3, max_steps).reason == "failed"
    finally:
        NutAndPegEnv._place_stalled = original
    env.close()
