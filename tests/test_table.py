"""igen-table end to end in a reduced configuration: every variant's dataset is built, trained with
lerobot-train, evaluated with igen-eval, and the table + JSON are written; a rerun resumes.

This checks the pipeline, not the success rates (a few training steps make no useful policy);
the full table is a documented command (docs/results.md)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

from igen_lerobot.core.paper import VARIANTS
from igen_lerobot.datasets.reader import load_episodes
from igen_lerobot.experiments.table import LABELS

ENV = {**os.environ, "MUJOCO_GL": "egl", "HF_HUB_OFFLINE": "1"}


def test_reduced_table_builds_trains_evaluates_and_resumes(tmp_path):
    from lerobot_env_igen.block_grasp.spec import SPEC

    out, results = tmp_path / "table", tmp_path / "results.md"
    cmd = [
        str(Path(sys.executable).parent / "igen-table"),
        "--source_episodes=2",
        "--base_demos=4",
        "--generated=3",
        "--train.steps=2",
        "--train.batch_size=8",
        "--train.num_workers=0",
        "--n_trials=2",
        "--workers=1",
        "--in_process=true",
        f"--output_dir={out}",
        f"--results={results}",
    ]
    first = subprocess.run(cmd, capture_output=True, text=True, timeout=1200, env=ENV)
    assert first.returncode == 0, first.stderr[-4000:]

    report = json.loads((tmp_path / "results" / "block_grasp.json").read_text())
    assert [row["variant"] for row in report["rows"]] == list(VARIANTS)
    markdown = results.read_text()
    for row in report["rows"]:
        low, high = row["ci95"]
        assert 0 <= low <= row["success_rate"] <= high <= 1 and row["trials"] == 2
        assert f"| {LABELS[row['variant']]} |" in markdown
    tools = {c["command"].split()[0] for c in report["commands"]}
    assert tools == {"igen-collect", "igen-generate", "igen-merge", "lerobot-train", "igen-eval"}
    assert "lerobot-train --policy.type=bc_rnn" in markdown

    # every variant trained on D plus its own part; the base policy on D alone
    sizes = {row["variant"]: row["dataset"]["episodes"] for row in report["rows"]}
    assert sizes["base"] == 4
    assert sizes["source_int"] == sizes["source_demo"] == 4 + 2
    assert sizes["weighted_src_int"] >= sizes["source_int"]
    assert sizes["mg_demo"] == sizes["igen_no_policy"] == sizes["igen"] == 4 + 3
    # base demonstrations observe true poses; the test-time demonstrations observe the corrupted ones
    believed = slice(0, 3)
    for ep in load_episodes(out / "data" / "source_demos", SPEC):
        assert np.allclose(ep.env_state[0, believed], ep.true_object_pose[0, :3], atol=1e-6)
    for ep in load_episodes(out / "data" / "test_demos", SPEC):
        assert not np.allclose(ep.env_state[0, believed], ep.true_object_pose[0, :3], atol=1e-3)
        assert np.allclose(ep.env_state[0, believed] - ep.true_object_pose[0, :3], ep.corruption, atol=1e-5)

    # rerun: everything is found complete, nothing is redone, same numbers
    again = subprocess.run(cmd, capture_output=True, text=True, timeout=600, env=ENV)
    assert again.returncode == 0, again.stderr[-4000:]
    rerun = json.loads((tmp_path / "results" / "block_grasp.json").read_text())
    # nothing redone: the step times on record are still the first run's, one per step that ran
    assert rerun["step_times_s"] == report["step_times_s"]
    assert {c["step"] for c in rerun["commands"]} == set(report["step_times_s"])
    assert [r["success_rate"] for r in rerun["rows"]] == [r["success_rate"] for r in report["rows"]]


def test_shipped_results_are_what_igen_table_renders_from_their_json():
    """docs/results.md is the page igen-table renders from docs/results/*.json: no hand-edited numbers."""
    from igen_lerobot.experiments.table import load_results, render_markdown, render_page

    docs = Path(__file__).resolve().parents[1] / "docs"
    tables = load_results(docs / "results")
    by_name = {result["name"]: result for result, _ in tables}
    assert [row["variant"] for row in by_name["block_grasp"]["rows"]] == list(VARIANTS)
    assert (docs / "results.md").read_text() == render_page(tables)
    result = by_name["block_grasp"]
    every_second = {**result, "config": {**result["config"], "eval_every": 2}}
    assert "one in every 2 saved checkpoints, 50 trials" in "\n".join(render_markdown(every_second))
