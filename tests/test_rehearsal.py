"""igen-rehearse: a finished table's chosen checkpoints through igen-eval and the deployment paths.

The end-to-end runs use a fake table whose rows all chose the tiny BC-RNN checkpoint of
``bc_rnn_checkpoint`` (the plumbing, not the rates), one trial and short episodes.
"""

from __future__ import annotations

import json
import os
from dataclasses import asdict
from pathlib import Path

import pytest

from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.experiments.config_rehearsal import PATHS, RehearsalConfig
from igen_lerobot.experiments.config_table import TableConfig
from igen_lerobot.experiments.provenance import provenance_problems
from igen_lerobot.experiments.rehearsal_report import ordering
from igen_lerobot.experiments.table_report import render_page
from igen_lerobot.training.config_train import TrainConfig

ROWS = ["base", "igen"]
SEEDS = [7, 8]


def fake_table(tmp_path: Path, checkpoint: Path) -> Path:
    """A table dir laid out as igen-table leaves it, whose runs of ROWS (seeds 7, 8) all chose ``checkpoint``."""
    train_out = checkpoint.parents[2]  # <output_dir>/checkpoints/<step>/pretrained_model (not last/)
    step = int(checkpoint.parent.name)
    table = tmp_path / "table"
    cfg = TableConfig(train=TrainConfig(steps=step), train_seeds=SEEDS, n_val_trials=1)
    table.mkdir()
    (table / "table_config.json").write_text(json.dumps(asdict(cfg)))
    for row in ROWS:
        (table / "train" / row).mkdir(parents=True)
        for seed in SEEDS:
            (table / "train" / row / f"seed{seed}").symlink_to(train_out)
            result = {"policy": str(checkpoint), "trials": 1, "successes": 0, "success_rate": 0.0, "ci95": [0, 0.79]}
            result |= {"mean_steps": 10.0, "seconds": 1.0, "per_trial": [False], "step": step}
            validation = table / "eval" / row / f"seed{seed}" / "validation.json"
            validation.parent.mkdir(parents=True)
            validation.write_text(json.dumps({"results": [result]}))
    return table


def rehearse(table: Path, tmp_path: Path, paths: list[str], **kwargs) -> dict:
    from igen_lerobot.experiments.rehearsal import run_rehearsal

    cfg = RehearsalConfig(
        table_dir=str(table),
        rows=ROWS,
        trials=1,
        paths=paths,
        max_steps=20,
        in_process=True,
        results=str(tmp_path / "results.md"),
        **kwargs,
    )
    return run_rehearsal(cfg)


def check_report(result: dict, table: Path, tmp_path: Path, paths: list[str], seeds: list[int] = SEEDS) -> None:
    """A row per (row, path) pooling every training seed, the same trials everywhere, the page from the JSON."""
    assert [(r["variant"], r["path"]) for r in result["results"]] == [(row, p) for row in ROWS for p in paths]
    trial_seeds = {json.dumps(r["trial_seeds"]) for r in result["results"]}
    assert len(trial_seeds) == 1 and len(json.loads(trial_seeds.pop())) == 1
    for entry in result["results"]:
        low, high = entry["ci95"]
        assert entry["trials"] == len(seeds) and 0 <= low <= entry["success_rate"] <= high <= 1
        assert [s["seed"] for s in entry["per_seed"]] == seeds
        assert entry["successes"] == sum(s["successes"] for s in entry["per_seed"])
        assert all(s["trials"] == 1 and len(s["per_trial"]) == 1 for s in entry["per_seed"])
    assert result["trial_seed"] == TableConfig().test_seed and result["seeds"] == seeds
    assert f"({', '.join(map(str, seeds))}); a cell pools their trials" in result["checkpoint_choice"]
    assert result["trial_choice"].startswith("the table's test trials (seed 2000003)")
    assert set(result["step_times_s"]) == {f"{p}_{row}_seed{s}" for row in ROWS for p in paths for s in seeds}
    assert set(result["step_cpu_s"]) == set(result["step_times_s"])
    assert all(t > 0 for t in result["step_cpu_s"].values())
    page = (tmp_path / "results.md").read_text()
    steps = ", ".join(["3"] * len(seeds))
    assert "rehearsal: the sim-to-real rows" in page and f"| I-Gen | {steps} |" in page
    saved = json.loads((tmp_path / "results" / "block_grasp_rehearsal.json").read_text())
    assert saved["results"] == result["results"]
    problems = provenance_problems(saved)
    assert all("uncommitted changes" in p for p in problems), problems  # a developer's tree may be dirty


def test_rehearsal_runs_igen_eval_and_the_mujoco_arm_on_the_same_trials_and_resumes(bc_rnn_checkpoint, tmp_path):
    table = fake_table(tmp_path, Path(bc_rnn_checkpoint).resolve())
    paths = ["eval", "rendered"]
    result = rehearse(table, tmp_path, paths)
    check_report(result, table, tmp_path, paths)
    out = table / "rehearsal"
    times = (out / "step_times.json").read_text()
    reports = {p: p.stat().st_mtime_ns for p in (out / "reports").rglob("*.json")}
    assert (
        len(reports) == len(ROWS) * len(SEEDS) * len(paths)
        and json.loads((out / "step_commits.json").read_text()).keys() == json.loads(times).keys()
    )

    again = rehearse(table, tmp_path, paths)  # nothing to redo
    assert (out / "step_times.json").read_text() == times
    assert {p: p.stat().st_mtime_ns for p in (out / "reports").rglob("*.json")} == reports
    assert again["results"] == result["results"]

    # an interrupted step (no report) is redone, alone
    (out / "reports" / "igen" / "seed8" / "rendered.json").unlink()
    rehearse(table, tmp_path, paths)
    redone = json.loads((out / "step_times.json").read_text())
    assert [s for s, t in redone.items() if t != json.loads(times)[s]] == ["rendered_igen_seed8"]

    # one training seed, in a rehearsal of its own (a resumed one refuses other seeds)
    with pytest.raises(ConfigError, match=r"seeds: \[7, 8\] -> \[8\]"):
        rehearse(table, tmp_path, paths, seeds=[8])
    alone = rehearse(table, tmp_path, ["eval"], seeds=[8], output_dir=str(tmp_path / "seed8"))
    check_report(alone, table, tmp_path, ["eval"], seeds=[8])
    with pytest.raises(ConfigError, match=r"--seeds: \[9\] are not among the table's training seeds \[7, 8\]"):
        rehearse(table, tmp_path, ["eval"], seeds=[9], output_dir=str(tmp_path / "seed9"))


@pytest.mark.realtime
def test_rehearsal_runs_franky_on_franky_sim_started_by_itself(bc_rnn_checkpoint, tmp_path):
    from lerobot_robot_igen.arm.franky_sim_server import free_loopback

    table = fake_table(tmp_path, Path(bc_rnn_checkpoint).resolve())
    paths = ["eval", "franky"]
    port = 20000 + (os.getpid() + 7) % 20000
    # one training seed: every seed runs the same path (the MuJoCo-arm test runs both), and each franky
    # trial costs its moves home in real time
    where = {"franky_host": free_loopback(), "franky_scene_port": port, "seeds": [8]}
    result = rehearse(table, tmp_path, paths, **where)
    check_report(result, table, tmp_path, paths, seeds=[8])
    assert "READY" in (table / "rehearsal" / "logs" / "franky_sim.log").read_text()
    times = (table / "rehearsal" / "step_times.json").read_text()
    rehearse(table, tmp_path, paths, **where)  # no server is started
    assert (table / "rehearsal" / "step_times.json").read_text() == times


def test_a_stopped_deploy_runs_report_is_kept_aside_and_a_rerun_redoes_it(tmp_path):
    """igen-deploy writes the trials of a run it stopped, then fails: the evidence stays, the step is redone."""
    from igen_lerobot.experiments.ledger import Ledger
    from igen_lerobot.experiments.rehearsal import run_step
    from igen_lerobot.experiments.step_runner import StepFailedError, StepRunner

    out, ledger = tmp_path / "out", tmp_path / "ledger"
    runner = StepRunner(out, ledger=Ledger(ledger, out))
    report = out / "rehearsal" / "reports" / "igen" / "seed8" / "franky.json"
    report.parent.mkdir(parents=True)
    stopped_run = ["sh", "-c", f'echo \'{{"stopped": {{"before_trial": 17}}}}\' > {report}; exit 1']
    with pytest.raises(StepFailedError, match="franky.stopped.json"):
        run_step(runner, "rehearse_franky_igen_seed8", stopped_run, report)
    kept = report.with_name("franky.stopped.json")
    assert not report.exists()  # a rerun must not take the stopped run for a finished one
    assert json.loads(kept.read_text()) == {"stopped": {"before_trial": 17}}
    assert (ledger / kept.relative_to(out)).read_text() == kept.read_text()  # kept across machines too

    with pytest.raises(StepFailedError, match="franky.stopped2.json"):  # a second stop keeps the first's report
        run_step(runner, "rehearse_franky_igen_seed8", stopped_run, report)
    assert json.loads(kept.read_text()) == {"stopped": {"before_trial": 17}}

    run_step(runner, "rehearse_franky_igen_seed8", ["sh", "-c", f"echo '{{\"stopped\": null}}' > {report}"], report)
    assert json.loads(report.read_text()) == {"stopped": None} and kept.exists()


def test_a_resumed_rehearsal_refuses_settings_that_change_finished_steps(tmp_path):
    from igen_lerobot.experiments.rehearsal import check_resumed

    settings = {"table_dir": "t", "seeds": [0], "trial_seed": 1, "trials": 20, "max_steps": 200, "device": "cpu"}
    check_resumed(tmp_path, settings)
    check_resumed(tmp_path, settings)
    with pytest.raises(ConfigError, match="trials: 20 -> 5"):
        check_resumed(tmp_path, {**settings, "trials": 5})


def test_rehearsal_config_names_the_fix():
    with pytest.raises(ConfigError, match="--table_dir is required"):
        RehearsalConfig()
    with pytest.raises(ConfigError, match=r"--paths must be distinct names among \['eval', 'rendered', 'franky'\]"):
        RehearsalConfig(table_dir="x", paths=["mujoco"])
    assert RehearsalConfig(table_dir="x", paths=["franky", "eval"]).paths == ["eval", "franky"]
    with pytest.raises(ConfigError, match=r"--seeds must be distinct training seeds of the table, got \[1, 1\]"):
        RehearsalConfig(table_dir="x", seeds=[1, 1])


def test_a_table_dir_that_is_not_a_block_grasp_table_is_refused(tmp_path):
    from igen_lerobot.experiments.rehearsal import read_table_config

    with pytest.raises(ConfigError, match="holds no igen-table run"):
        read_table_config(tmp_path)
    (tmp_path / "table_config.json").write_text(json.dumps(asdict(TableConfig(task="nut_insertion"))))
    with pytest.raises(ConfigError, match="needs igen-table --task=block_grasp"):
        read_table_config(tmp_path)


# ------------------------------------------------------------------------------ rendering, synthetic JSON
PAPER = {"base": (6, 0), "source_int": (26, 10), "mg_demo": (42, 50), "igen_no_policy": (86, 60), "igen": (100, 90)}
LABELS = {"base": "Base", "source_int": "Source Int", "mg_demo": "MG Demo", "igen_no_policy": "I-Gen − Policy"}


def synthetic(successes: dict[str, tuple[int, int, int]], n: int = 20) -> dict:
    """A rehearsal JSON as igen-rehearse writes it, with made-up successes per row (eval, rendered, franky)."""
    from igen_lerobot.evaluation.trials import wilson_interval

    rows = []
    for variant, counts in successes.items():
        results = {
            path: {"successes": k, "trials": n, "success_rate": k / n, "ci95": list(wilson_interval(k, n))}
            for path, k in zip(PATHS, counts, strict=True)
        }
        sim, real = PAPER[variant]
        label = LABELS.get(variant, "I-Gen")
        rows.append({"variant": variant, "label": label, "chosen_steps": [1500], "paper_sim": sim, "paper_real": real})
        rows[-1]["results"] = results
    step_code = {f"{p}_{v}": {"commit": "a" * 40, "dirty": False} for v in successes for p in PATHS}
    return {
        "kind": "rehearsal",
        "task": "block_grasp",
        "name": "block_grasp_rehearsal",
        "checkpoint_choice": "the one igen-table chose for each training seed of the table (1000)",
        "trials": n,
        "trial_seed": 2_000_003,
        "trial_choice": "the table's test trials (seed 2000003), which no checkpoint choice saw",
        "max_steps": 200,
        "paths": dict(PATHS),
        "paper": {"sim_trials": 50, "real_trials": 10},
        "rows": rows,
        "step_code": step_code,
        "commands": [{"step": s, "command": f"igen-eval {s}"} for s in step_code],
        "wall_time_s": 600.0,
        "step_times_s": dict.fromkeys(step_code, 60.0),
    }


def test_the_page_renders_a_rehearsal_beside_the_papers_columns_with_the_ordering_rule():
    result = synthetic(
        {
            "base": (1, 0, 0),
            "source_int": (5, 4, 2),
            "mg_demo": (9, 10, 12),
            "igen_no_policy": (17, 11, 12),
            "igen": (20, 19, 18),
        }
    )
    page = render_page([(result, "A reading.")])
    assert "## Block Grasp rehearsal: the sim-to-real rows through the deployment paths" in page
    header = next(line for line in page.splitlines() if line.startswith("| Variant |"))
    assert header.startswith("| Variant | chosen steps |")
    assert header.endswith("| paper sim (50) | paper real (10) |") and all(label in header for label in PATHS.values())
    assert "| Base | 1500 | 1/20 (1–24%) | 0/20 (0–16%) | 0/20 (0–16%) | 6% | 0% |" in page
    assert "| I-Gen | 1500 | 20/20 (84–100%) | 19/20 (76–99%) | 18/20 (70–97%) | 100% | 90% |" in page
    assert "(Base < Source Int < MG Demo < I-Gen − Policy < I-Gen)" in page
    assert f"- {PATHS['eval']}: holds (strictly increasing)." in page
    assert f"- {PATHS['rendered']}: holds (strictly increasing)." in page
    assert f"- {PATHS['franky']}: does not hold (MG Demo and I-Gen − Policy equal)." in page
    assert "A reading." in page
    assert "- Code: every step ran at commit aaaaaaaaaa." in page
    # a table generated on randomised arms (igen-table --randomize) says so in its rehearsal's title
    result["table"] = {"randomize": ["--env.randomize.latency=[0,0.04]"]}
    page = render_page([(result, "")])
    assert "## Block Grasp rehearsal, generated on randomised arms (`--env.randomize.latency=[0,0.04]`): the" in page


def test_the_ordering_rule_names_inversions_and_skips_a_path_some_row_lacks():
    result = synthetic({"base": (3, 3, 3), "source_int": (2, 2, 2), "igen": (20, 20, 20)})
    assert ordering(result["rows"], "eval") == {
        "order": ["base", "source_int", "igen"],
        "holds": False,
        "inversions": [["base", "source_int"]],
        "ties": [],
    }
    del result["rows"][0]["results"]["franky"]
    assert ordering(result["rows"], "franky") is None
    page = "\n".join(render_page([(result, "")]).splitlines())
    assert f"- {PATHS['eval']}: does not hold (Source Int below Base)." in page
    assert f"- {PATHS['franky']}: not measured on every row." in page
    assert "| Base | 1500 | 3/20 (5–36%) | 3/20 (5–36%) | – |" in page


def test_a_cell_pools_the_training_seeds_and_shows_each_seeds_count():
    from igen_lerobot.evaluation.trials import wilson_interval

    result = synthetic({"base": (1, 0, 0), "igen": (20, 19, 18)})
    igen = result["rows"][1]
    igen["chosen_steps"] = [2000, 2000, 1500]
    per_seed = [
        {"seed": s, "chosen_step": 2000, "successes": k, "trials": 20} for s, k in ((1000, 19), (1001, 16), (1002, 15))
    ]
    igen["results"]["franky"] = {"successes": 50, "trials": 60, "success_rate": 50 / 60}
    igen["results"]["franky"] |= {"ci95": list(wilson_interval(50, 60)), "per_seed": per_seed}
    page = render_page([(result, "")])
    assert (
        "| I-Gen | 2000, 2000, 1500 | 20/20 (84–100%) | 19/20 (76–99%) | 50/60 (72–91%) [19, 16, 15] | 100% | 90% |"
        in page
    )
