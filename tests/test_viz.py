"""Rerun recordings of our data, read back with Rerun's own reader (rerun.experimental.RrdReader)."""

from __future__ import annotations

import subprocess
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np
import pytest

from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.datasets.reader import load_episodes
from igen_lerobot.viz.phases import RECOVERY_PHASES, Phase, phase_colors
from igen_lerobot.viz.replay import replay_dataset
from igen_lerobot.viz.rerun_log import RerunConfig

BIN = Path(sys.executable).parent


def read_rrd(path: Path) -> dict[str, list]:
    """entity path -> its record batches (Rerun's reader: no byte grepping)."""
    from rerun.experimental import RrdReader

    chunks = defaultdict(list)
    for chunk in RrdReader(path).stream():
        chunks[chunk.entity_path].append(chunk)
    return chunks


def column(chunks: list, name: str) -> list:
    values = []
    for chunk in chunks:
        batch = chunk.to_record_batch()
        if name in batch.schema.names:
            values.extend(batch.column(name).to_pylist())
    return values


def packed(rgb) -> int:
    """Rerun stores colours as 0xRRGGBBAA."""
    r, g, b = (int(c) for c in rgb)
    return (r << 24) | (g << 16) | (b << 8) | 255


RECOVERY_COLORS = {packed(phase_colors(np.array([p]))[0]) for p in RECOVERY_PHASES}


def test_replayed_interventions_colour_exactly_the_flagged_frames(source_interventions, block_grasp_config, tmp_path):
    spec = block_grasp_config.task_spec
    episodes = load_episodes(source_interventions, spec)
    out = tmp_path / "interventions.rrd"
    result = replay_dataset(source_interventions, RerunConfig(mode="save", path=str(out)), episodes=[0, 3])
    assert result["episodes"] == 2
    chunks = read_rrd(out)
    for index in (0, 3):
        episode = next(e for e in episodes if e.extra["episode_index"] == index)
        root = f"/episodes/{index}"
        # the static path: one point per frame, recovery colours on exactly the flagged frames
        colors = column(chunks[f"{root}/path"], "Points3D:colors")[0]
        assert len(colors) == episode.length
        recovery = [c in RECOVERY_COLORS for c in colors]
        assert sum(recovery) == int(episode.is_intervention.sum()) > 0
        np.testing.assert_array_equal(recovery, episode.is_intervention)
        # the mistake before the takeover is coloured as such (policy frames after the first contact)
        mistake = packed(phase_colors(np.array([Phase.MISTAKE]))[0])
        revealed_policy = (episode.env_state[:, -1] > 0.5) & (episode.source == 0)
        assert sum(c == mistake for c in colors) == int(revealed_policy.sum())
        # a timeline per frame for the end effector, the believed and the true cube
        for entity in ("eef", "cube/believed", "cube/true"):
            frames = column(chunks[f"{root}/{entity}"], "frame")
            assert frames == list(range(episode.length)), entity
        believed = np.array(column(chunks[f"{root}/cube/believed"], "Boxes3D:centers")).reshape(-1, 3)
        true = np.array(column(chunks[f"{root}/cube/true"], "Boxes3D:centers")).reshape(-1, 3)
        # before the reveal the robot believed a wrong pose: by this episode's corruption
        np.testing.assert_allclose(believed[0] - true[0], episode.corruption, atol=1e-5)
        assert np.linalg.norm(episode.corruption) > 0.02
        # the events: first contact, takeover, success
        events = [text for row in column(chunks[f"{root}/events"], "TextLog:text") for text in row]
        assert any("first contact" in e for e in events) and any("takeover" in e for e in events)
        assert events[-1] == ("end: success" if episode.success else "end: failure")
        assert len(column(chunks[f"{root}/action/delta.x"], "Scalars:scalars")) == episode.length


def test_demos_have_no_recovery_colour(source_demos, tmp_path):
    out = tmp_path / "demos.rrd"
    replay_dataset(source_demos, RerunConfig(mode="save", path=str(out)), episodes=[0])
    colors = column(read_rrd(out)["/episodes/0/path"], "Points3D:colors")[0]
    assert colors and not any(c in RECOVERY_COLORS for c in colors)


def test_igen_viz_cli_writes_a_recording_and_names_missing_fields(source_interventions, tmp_path):
    out = tmp_path / "cli.rrd"
    result = subprocess.run(
        [str(BIN / "igen-viz"), f"--dataset.root={source_interventions}", "--episodes=[1]", f"--output={out}"],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert result.returncode == 0, result.stderr[-2000:]
    assert "Replayed 1 episodes" in result.stdout
    assert {k for k in read_rrd(out) if k.startswith("/episodes/")} >= {"/episodes/1/path", "/episodes/1/eef"}
    with pytest.raises(ConfigError, match="--output"):
        from igen_lerobot.viz.config_viz import VizConfig, VizDatasetConfig

        VizConfig(dataset=VizDatasetConfig(root=str(source_interventions)))
    with pytest.raises(ConfigError, match="rerun.path"):
        RerunConfig(mode="save")


def test_live_logging_during_generation(source_interventions, tmp_path):
    """igen-generate --rerun.mode=save logs every kept episode as it finishes, with the source recoveries used."""
    out = tmp_path / "live.rrd"
    result = subprocess.run(
        [
            str(BIN / "igen-generate"),
            "--task=block_grasp",
            "--mode=igen",
            f"--source.root={source_interventions}",
            "--num_episodes=3",
            f"--dataset.root={tmp_path / 'generated'}",
            "--rerun.mode=save",
            f"--rerun.path={out}",
        ],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert result.returncode == 0, result.stderr[-3000:]
    chunks = read_rrd(out)
    logged = {k.split("/")[2] for k in chunks if k.startswith("/episodes/")}
    assert len(logged) >= 3
    assert any(k.startswith("/sources/") for k in chunks), "the source recoveries replayed are shown"
    for index in logged:
        colors = column(chunks[f"/episodes/{index}/path"], "Points3D:colors")[0]
        generated = packed(phase_colors(np.array([Phase.GENERATED]))[0])
        assert sum(c == generated for c in colors) > 0  # a generated recovery in every kept episode


def test_live_logging_during_evaluation(tmp_path):
    """igen-eval --rerun.mode=save logs each trial's path, belief and outcome."""
    out = tmp_path / "eval.rrd"
    result = subprocess.run(
        [
            str(BIN / "igen-eval"),
            "--task=block_grasp",
            "--n_trials=2",
            "--rerun.mode=save",
            f"--rerun.path={out}",
        ],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert result.returncode == 0, result.stderr[-3000:]
    chunks = read_rrd(out)
    for trial in (0, 1):
        root = f"/episodes/scripted/{trial}"
        frames = column(chunks[f"{root}/eef"], "frame")
        colors = column(chunks[f"{root}/path"], "Points3D:colors")[0]
        assert len(colors) == len(frames) > 0
        assert not any(c in RECOVERY_COLORS for c in colors)  # nobody intervenes in an evaluation
        assert column(chunks[f"{root}/cube/believed"], "Boxes3D:centers")
    outcomes = [text for row in column(chunks["/outcomes"], "TextLog:text") for text in row]
    assert len(outcomes) == 2 and all("scripted" in text for text in outcomes)
