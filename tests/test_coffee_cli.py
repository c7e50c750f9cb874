"""Coffee through the commands a user runs, kept small (two episodes each, one worker): igen-collect
(demos and human-gated interventions), igen-generate (all three modes, the scripted base policy for
IntervenGen), igen-eval of the scripted policy, igen-render (agentview + wrist), igen-viz and the
recovery picture, and LeRobot's lerobot-train + lerobot-eval on the task's env plugin.

Every command calls its console entry point in this process (same arguments, same code) to spare
~15 s of imports each; tests/test_nut_insertion_cli.py and tests/test_two_piece_assembly_cli.py run
the console scripts themselves as subprocesses.
"""

import json

import numpy as np
import pytest
from test_nut_insertion_cli import ok, run_here

from igen_lerobot.core.episode import EpisodeKind
from igen_lerobot.core.task import FrameSource
from igen_lerobot.datasets.reader import dataset_spec, load_episodes

TASK = "--env.type=coffee"


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    """Sources recorded with igen-collect (scripted operator) and a dataset of each generation mode."""
    root = tmp_path_factory.mktemp("coffee")
    ok(run_here("igen-collect", TASK, "--mode=demos", "--num_episodes=2", f"--dataset.root={root / 'demos'}"))
    ok(run_here("igen-collect", TASK, "--mode=interventions", "--num_episodes=2", f"--dataset.root={root / 'int'}"))
    for mode, source in (("mimicgen", "demos"), ("igen", "int"), ("igen_no_policy", "int")):
        ok(
            run_here(
                "igen-generate",
                f"--mode={mode}",
                TASK,
                f"--source.root={root / source}",
                "--num_episodes=2",
                "--workers=1",
                f"--dataset.root={root / mode}",
            )
        )
    return root


def test_collect_records_demos_and_interventions(data):
    spec = dataset_spec(data / "demos")
    assert spec.name == "coffee" and spec.objects == ("pod", "machine") and len(spec.action_names) == 7
    assert spec.corruption_names == ("machine.dx", "machine.dy", "machine.dz")
    assert all(ep.success and ep.kind == EpisodeKind.DEMO for ep in load_episodes(data / "demos", spec))
    for ep in load_episodes(data / "int", spec):
        assert ep.success and ep.kind == EpisodeKind.INTERVENTION
        takeover = int(np.flatnonzero(ep.is_intervention)[0])
        # the operator took over at the pod-machine contact that revealed, after the policy's frames
        assert ep.env_state[takeover, spec.env_state_index("revealed")] == 1.0
        assert np.all(ep.source[:takeover] == FrameSource.POLICY)


def test_generate_writes_all_three_modes(data):
    spec = dataset_spec(data / "demos")
    for mode, kind in (
        ("mimicgen", EpisodeKind.MIMICGEN),
        ("igen", EpisodeKind.IGEN),
        ("igen_no_policy", EpisodeKind.IGEN_NO_POLICY),
    ):
        episodes = load_episodes(data / mode, spec)
        assert len(episodes) == 2 and all(ep.kind == kind and ep.success for ep in episodes)
    for ep in load_episodes(data / "igen", spec):
        assert ep.is_intervention[0] and ep.env_state[0, spec.env_state_index("revealed")] == 1.0
    for ep in load_episodes(data / "igen_no_policy", spec):
        assert not (ep.source == FrameSource.POLICY).any()
    meta = json.loads((data / "igen" / "meta" / "igen.json").read_text())
    assert meta["task"] == "coffee" and meta["reveal"] == "full"


def test_eval_of_the_scripted_policy_and_render_of_both_cameras(data, tmp_path):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    report = tmp_path / "eval.json"
    ok(run_here("igen-eval", TASK, "--n_trials=2", f"--output={report}"))
    result = json.loads(report.read_text())
    assert result["task"] == "coffee" and result["best"]["trials"] == 2
    assert result["corruption"] == {**result["corruption"], "type": "radial", "r_min": 0.02, "r_max": 0.04}
    out = tmp_path / "rgb"
    ok(run_here("igen-render", f"--dataset.root={data / 'demos'}", "--cameras=[agentview,wrist]", "--size=32",
                f"--output.root={out}"))  # fmt: skip
    rendered = LeRobotDataset("local/rgb", root=out)
    assert {"observation.images.agentview", "observation.images.wrist"} <= set(rendered.meta.features)
    assert rendered.meta.total_frames == LeRobotDataset("local/d", root=data / "demos").meta.total_frames


def test_viz_and_the_recovery_picture_show_the_believed_and_true_machine(data, tmp_path):
    """igen-viz draws the machine where it was believed and where it was; the README's recovery
    picture (scripts/recovery_picture.sh) puts the believed machine at the true one plus the episode's
    error, since a generated recovery starts already revealed (exact: the same numbers added)."""
    from test_viz import column, read_rrd

    from igen_lerobot.viz.picture import believed_position, draw_episode

    ok(run_here("igen-viz", f"--dataset.root={data / 'igen'}", "--episodes=[0]", f"--output={tmp_path / 'out.rrd'}"))
    chunks = read_rrd(tmp_path / "out.rrd")
    for which in ("true", "believed"):
        half = column(chunks[f"/episodes/0/machine/{which}"], "Boxes3D:half_sizes")
        np.testing.assert_allclose(np.array(half[0][0]), [0.067, 0.045, 0.045], atol=1e-6)
    spec = dataset_spec(data / "igen")
    (episode,) = load_episodes(data / "igen", spec, episodes=[0])
    k = spec.objects.index("machine")
    revealed = spec.revealed_flags(episode.env_state)
    assert revealed[0]
    true = episode.true_object_pose[0, 7 * k : 7 * k + 3]
    believed = believed_position(episode, k, revealed)
    np.testing.assert_array_equal(believed, true + episode.corruption)
    assert 0.02 - 1e-9 <= np.linalg.norm(believed[:2] - true[:2]) <= 0.04 + 1e-9  # the radial error
    picture = tmp_path / "recovery.png"
    draw_episode(episode, spec, picture, "coffee")
    assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and picture.stat().st_size > 10_000


def lerobot_train_and_eval(dataset, task: str, tmp_path) -> dict:
    """LeRobot's own lerobot-train (2 BC-RNN steps: plumbing, not quality) on ``dataset``, then
    lerobot-eval of the checkpoint on ``task``'s env plugin for one short episode; its eval_info."""
    ok(run_here("lerobot-train", "--policy.type=bc_rnn", "--dataset.repo_id=local/mimicgen",
                f"--dataset.root={dataset}", "--steps=2", "--batch_size=4", "--policy.device=cpu",
                f"--output_dir={tmp_path / 'train'}", "--policy.push_to_hub=false", "--save_freq=2", "--num_workers=0",
                "--wandb.enable=false"))  # fmt: skip
    checkpoint = tmp_path / "train/checkpoints/last/pretrained_model"
    ok(run_here("lerobot-eval", f"--policy.path={checkpoint}", task, "--env.episode_length=10", "--eval.n_episodes=1",
                "--eval.batch_size=1", "--policy.device=cpu", f"--output_dir={tmp_path / 'eval'}"))  # fmt: skip
    return json.loads((tmp_path / "eval/eval_info.json").read_text())


def test_lerobot_train_and_lerobot_eval_run_on_the_task(data, tmp_path):
    info = lerobot_train_and_eval(data / "mimicgen", TASK, tmp_path)
    assert info["overall"]["n_episodes"] == 1
