"""Nut Insertion through every command a user runs: igen-collect (demos and human-gated interventions),
igen-generate (all three modes), igen-eval, lerobot-train + lerobot-eval, igen-viz; and bad input from
the command line: a clear message naming the flag, nothing half-written.

The first command and LeRobot's own run as subprocesses; the others call the same console entry
points in this process (same arguments, same code) to spare ~15 s of imports each.
"""

import contextlib
import io
import json
import os
import re
import subprocess
import sys
from importlib.metadata import entry_points
from pathlib import Path

import numpy as np
import pytest

from igen_lerobot.core.episode import EpisodeKind
from igen_lerobot.core.task import FrameSource
from igen_lerobot.datasets.reader import dataset_spec, load_episodes

BIN = Path(sys.executable).parent
NUT = "--env.type=nut_insertion"


def run(*cmd, timeout=300):
    env = {**os.environ, "MUJOCO_GL": "egl", "HF_HUB_OFFLINE": "1"}
    return subprocess.run([str(BIN / cmd[0]), *cmd[1:]], env=env, capture_output=True, text=True, timeout=timeout)


def ok(result):
    assert result.returncode == 0, result.stderr[-3000:]
    return result


def run_here(*cmd):
    """A console script's entry point in this process: (exit status, what it wrote to stderr)."""
    main = next(iter(entry_points(group="console_scripts", name=cmd[0]))).load()
    saved, stderr = sys.argv, io.StringIO()
    sys.argv = list(cmd)
    try:
        with contextlib.redirect_stderr(stderr):
            main()
        code = 0
    except SystemExit as error:
        code = error.code if isinstance(error.code, int) else 1
    finally:
        sys.argv = saved
    return subprocess.CompletedProcess(cmd, code, "", stderr.getvalue())


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    """Sources recorded with igen-collect (scripted operator) and a dataset of each generation mode."""
    root = tmp_path_factory.mktemp("nut")
    collected = ok(run("igen-collect", NUT, "--mode=demos", "--num_episodes=3", f"--dataset.root={root / 'demos'}"))
    ok(run_here("igen-collect", NUT, "--mode=interventions", "--num_episodes=3", f"--dataset.root={root / 'int'}"))
    for mode, source in (("mimicgen", "demos"), ("igen", "int"), ("igen_no_policy", "int")):
        ok(
            run_here(
                "igen-generate",
                f"--mode={mode}",
                NUT,
                f"--source.root={root / source}",
                "--num_episodes=4",
                "--workers=1",  # the 2-worker path: test_generation_runner.py
                f"--dataset.root={root / mode}",
            )
        )
    return root, collected


def test_collect_records_demos_and_interventions_without_robosuite_notices(data):
    root, collected = data
    spec = dataset_spec(root / "demos")
    assert spec.name == "nut_insertion" and len(spec.action_names) == 7
    demos, interventions = load_episodes(root / "demos", spec), load_episodes(root / "int", spec)
    assert all(ep.success and ep.kind == EpisodeKind.DEMO and not ep.is_intervention.any() for ep in demos)
    for ep in interventions:
        assert ep.success and ep.kind == EpisodeKind.INTERVENTION
        takeover = int(np.flatnonzero(ep.is_intervention)[0])
        revealed = ep.env_state[:, spec.env_state_index("revealed")]
        assert revealed[takeover] == 1.0  # the operator took over at the nut-peg contact that revealed the peg
        assert np.all(ep.source[:takeover] == FrameSource.POLICY)
    # robosuite's import-time notices about parts we never use are not shown ...
    for notice in ("macro file", "robosuite_models", "mink"):
        assert notice not in collected.stderr
    # ... but robosuite's other messages still are
    from lerobot_env_igen.quiet import IrrelevantRobosuiteNotices

    keep = IrrelevantRobosuiteNotices()
    make = __import__("logging").LogRecord
    assert keep.filter(make("robosuite_logs", 30, __file__, 1, "Gripper clipped to range", None, None))
    assert not keep.filter(make("robosuite_logs", 30, __file__, 1, "No private macro file found!", None, None))


def test_generate_writes_all_three_modes(data):
    root, _ = data
    spec = dataset_spec(root / "demos")
    for mode, kind in (("mimicgen", EpisodeKind.MIMICGEN), ("igen", EpisodeKind.IGEN)):
        episodes = load_episodes(root / mode, spec)
        assert len(episodes) == 4 and all(ep.kind == kind and ep.success for ep in episodes)
    for ep in load_episodes(root / "igen", spec):
        assert ep.is_intervention[0]  # starts at the mistake, recovery first
        assert ep.env_state[0, spec.env_state_index("revealed")] == 1.0
    for ep in load_episodes(root / "igen_no_policy", spec):
        assert ep.kind == EpisodeKind.IGEN_NO_POLICY and not (ep.source == FrameSource.POLICY).any()
    meta = json.loads((root / "igen" / "meta" / "igen.json").read_text())
    assert meta["task"] == "nut_insertion" and meta["reveal"] == "full"
    assert meta["generation"]["success_rate"] > 0.5


def test_viz_draws_the_nut_and_peg_as_rotated_boxes(data, tmp_path):
    from test_viz import column, read_rrd

    root, _ = data
    ok(run_here("igen-viz", f"--dataset.root={root / 'igen'}", "--episodes=[0]", f"--output={tmp_path / 'out.rrd'}"))
    chunks = read_rrd(tmp_path / "out.rrd")
    half = column(chunks["/episodes/0/nut/true"], "Boxes3D:half_sizes")
    quats = column(chunks["/episodes/0/nut/true"], "Boxes3D:quaternions")
    assert half and quats
    np.testing.assert_allclose(np.array(half[0][0]), [0.0615, 0.04375, 0.01], atol=1e-6)
    # the nut lies with its handle towards the robot: a half turn about z
    assert abs(abs(np.array(quats[0][0])[2]) - 1.0) < 0.05
    peg = column(chunks["/episodes/0/peg/believed"], "Boxes3D:half_sizes")
    np.testing.assert_allclose(np.array(peg[0][0]), [0.016, 0.016, 0.065], atol=1e-6)


def test_igen_eval_and_lerobot_eval_run_a_trained_policy(data, tmp_path):
    root, _ = data
    ok(
        run(
            "lerobot-train",
            "--policy.type=bc_rnn",
            "--dataset.repo_id=local/mimicgen",
            f"--dataset.root={root / 'mimicgen'}",
            "--steps=2",
            "--batch_size=4",
            "--policy.device=cpu",
            f"--output_dir={tmp_path / 'train'}",
            "--policy.push_to_hub=false",
            "--save_freq=2",
            "--num_workers=0",
            "--wandb.enable=false",
        )
    )
    checkpoint = tmp_path / "train/checkpoints/last/pretrained_model"
    report = tmp_path / "eval.json"
    ok(run_here("igen-eval", NUT, f"--policy.path={checkpoint}", "--n_trials=2", f"--output={report}"))
    result = json.loads(report.read_text())
    assert result["task"] == "nut_insertion" and result["best"]["trials"] == 2
    assert result["corruption"]["type"] == "box" and result["corruption"]["half_extent"] == [0.04, 0.04, 0.04]
    ok(
        run(
            "lerobot-eval",
            f"--policy.path={checkpoint}",
            NUT,
            "--env.episode_length=10",
            "--eval.n_episodes=1",
            "--eval.batch_size=1",
            "--policy.device=cpu",
            f"--output_dir={tmp_path / 'lerobot_eval'}",
        )
    )
    info = json.loads((tmp_path / "lerobot_eval/eval_info.json").read_text())
    assert info["overall"]["n_episodes"] == 1


def _nothing_written(*roots):
    for root in roots:
        assert not root.exists() and not root.with_name(root.name + ".partial").exists()


def test_bad_sources_are_refused_before_anything_is_written(data, tmp_path, bc_rnn_checkpoint, source_demos):
    root, _ = data
    out = tmp_path / "out"
    cases = [
        (["--mode=igen", f"--source.root={tmp_path / 'nowhere'}"], "not a LeRobot dataset.*check --source.root"),
        (["--mode=igen", f"--source.root={source_demos}"], r"--source.root=.* holds task 'block_grasp'"),
        (["--mode=mimicgen", f"--source.root={root / 'int'}"], r"holds \['intervention'\] episodes; MimicGen"),
        (["--mode=igen", f"--source.root={root / 'demos'}"], "no intervention frames"),
        (
            ["--mode=igen", f"--source.root={root / 'int'}", f"--policy.path={bc_rnn_checkpoint}"],
            r"--policy.path=.* expects observation.environment_state of shape \(9,\); task 'nut_insertion' gives "
            r"\(16,\): train a policy on a dataset of this task",
        ),
        (["--mode=igen", f"--source.root={root / 'int'}", "--env.reveal=sideways"], "is not a reveal mode; use one"),
        (["--mode=igen", f"--source.root={root / 'int'}", "--env.corruption.type=flip"], "does not fit nut_insertion"),
    ]
    for args, message in cases:
        result = run_here("igen-generate", NUT, *args, "--num_episodes=2", f"--dataset.root={out}")
        assert result.returncode == 2, (args, result.stderr[-2000:])
        last = result.stderr.strip().splitlines()[-1]
        assert last.startswith("igen-generate: error:"), last
        assert re.search(message, last), (message, last)
        _nothing_written(out)
    evaluation = run_here("igen-eval", NUT, f"--policy.path={bc_rnn_checkpoint}", "--n_trials=1")
    assert evaluation.returncode == 2 and "of shape (9,); task 'nut_insertion' gives (16,)" in evaluation.stderr
