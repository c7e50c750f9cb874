"""igen-table end to end in a reduced configuration: every variant's dataset is built, trained with
lerobot-train, evaluated with igen-eval, and the table + JSON are written; a rerun resumes
with another training seed.

This checks the pipeline, not the success rates (a few training steps make no useful policy);
the full table is a documented command (docs/results.md)."""

import json
import os
import subprocess
import time
from dataclasses import asdict
from pathlib import Path

import numpy as np
import pytest

from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.core.paper import VARIANTS
from igen_lerobot.datasets.reader import load_episodes
from igen_lerobot.experiments.config_loop import LoopConfig
from igen_lerobot.experiments.config_table import TableConfig, TableTrainConfig
from igen_lerobot.experiments.provenance import code_version, provenance_problems
from igen_lerobot.experiments.table_steps import LABELS
from igen_lerobot.training.config_train import TrainConfig


def test_reduced_table_builds_trains_evaluates_and_resumes(tmp_path, tiny_table):
    """All seven rows on one training seed, then a resume that adds a second seed to two rows.

    The resume must redo nothing the first run finished, train only the new seed's runs, and pool
    each row over both seeds (one seed per row first keeps this end-to-end run to a few minutes).
    """
    from lerobot_env_igen.block_grasp.spec import SPEC

    out, results = tmp_path / "table", tmp_path / "results.md"
    first = tiny_table(out, results, "--generated=3", "--train_seeds=[7]", "--run_first=[igen]", timeout=360)
    assert first.returncode == 0, first.stderr[-4000:]

    report = json.loads((tmp_path / "results" / "block_grasp.json").read_text())
    # I-Gen was made first; its row keeps its place (and the resume below, without --run_first, is allowed)
    validations = [c["step"] for c in report["commands"] if c["step"].startswith("validate_")]
    assert validations[0] == "validate_igen_seed7" and len(validations) == len(VARIANTS)
    assert [row["variant"] for row in report["rows"]] == list(VARIANTS)
    markdown = results.read_text()
    for row in report["rows"]:
        assert [s["seed"] for s in row["seeds"]] == [7] and row["trials"] == 1
        low, high = row["ci95"]
        assert 0 <= low <= row["success_rate"] <= high <= 1
        seed = row["seeds"][0]
        # the checkpoint is the best on validation; the test trials are others, run on that checkpoint
        assert seed["validation_rate"] == max(seed["validation"].values())
        folder = out / "eval" / row["variant"] / "seed7"
        test = json.loads((folder / f"test_step{seed['chosen_step']}.json").read_text())
        validation = json.loads((folder / "validation.json").read_text())
        assert test["seed"] != validation["seed"] and test["n_trials"] == 1
        assert test["results"][0]["policy"].endswith(f"{seed['chosen_step']:06d}/pretrained_model")
        assert f"| {LABELS[row['variant']]} |" in markdown
    # the JSON names the code that made every step and the whole config
    assert report["code"] == code_version()
    problems = provenance_problems(report)
    if report["code"]["dirty"]:  # a developer's working tree: only the dirtiness may be missing
        assert problems and all("uncommitted changes" in p for p in problems)
    else:  # CI's clean clone
        assert problems == []
    assert set(report["step_code"]) == {c["step"] for c in report["commands"]}
    tools = {next(w for w in c["command"].split() if "=" not in w) for c in report["commands"]}
    assert tools == {"igen-collect", "igen-generate", "igen-merge", "lerobot-train", "igen-eval"}
    # every training runs at the table's fixed thread count (the weights differ between counts)
    trainings = [c["command"] for c in report["commands"] if c["step"].startswith("train_")]
    assert trainings and all(c.startswith("OMP_NUM_THREADS=2 lerobot-train ") for c in trainings)
    assert report["config"]["train"]["threads"] == 2
    assert "OMP_NUM_THREADS=2 lerobot-train --policy.type=bc_rnn" in markdown
    # every row's inputs are normalised with D's statistics; Base's own are D's, so it is not told
    normaliser = f"--policy.observation_stats={out / 'data' / 'base'}"
    for step in (c for c in report["commands"] if c["step"].startswith("train_")):
        assert (normaliser in step["command"]) == (not step["step"].startswith("train_base_")), step
    assert report["config"]["observation_stats"] == "base" and "with the base dataset D's statistics" in markdown
    # every step's CPU time is recorded beside its wall time: a step runs code, so it costs CPU, and
    # a step cannot use more CPU seconds than the machine's cores give it in its wall time
    assert set(report["step_cpu_s"]) == set(report["step_times_s"]) == set(report["step_code"])
    for step, cpu in report["step_cpu_s"].items():
        assert 0.0 < cpu <= (os.cpu_count() or 1) * report["step_times_s"][step] + 1.0, (step, cpu)
    assert "- CPU time (all steps): " in markdown

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

    # resume with a second seed on two rows: nothing finished is redone, the new seed trains its own runs
    again = tiny_table(out, results, "--generated=3", "--train_seeds=[7,8]", "--variants=[base,igen]", timeout=180)
    assert again.returncode == 0, again.stderr[-4000:]
    resumed = json.loads((tmp_path / "results" / "block_grasp.json").read_text())
    times = json.loads((out / "step_times.json").read_text())
    assert all(times[step] == t for step, t in report["step_times_s"].items())  # the first run's steps: not rerun
    new_steps = set(times) - set(report["step_times_s"])
    assert new_steps == {f"{kind}_{v}_seed8" for kind in ("train", "validate", "test") for v in ("base", "igen")}
    assert (out / "train" / "base" / "seed8").is_dir() and (out / "train" / "igen" / "seed8").is_dir()
    # the interventions still come from the first seed's base policy
    igen_cmd = next(c["command"] for c in resumed["commands"] if c["step"] == "igen")
    assert "train/base/seed7/" in igen_cmd
    first_rates = {row["variant"]: row["seeds"][0]["test"] for row in report["rows"]}
    assert [row["variant"] for row in resumed["rows"]] == ["base", "igen"]
    for row in resumed["rows"]:
        # two training seeds, each tested on one trial: the interval is on the 2 pooled trials
        assert [s["seed"] for s in row["seeds"]] == [7, 8] and row["trials"] == 2
        assert row["seeds"][0]["test"] == first_rates[row["variant"]]  # seed 7's numbers, read back, not remade
        rates = [s["test"]["success_rate"] for s in row["seeds"]]
        assert row["success_rate"] == sum(rates) / 2 and row["min"] == min(rates) and row["max"] == max(rates)
        low, high = row["ci95"]
        assert 0 <= low <= row["success_rate"] <= high <= 1

    # a rerun with every step done (a chain of tables resuming) leaves the table's record as it was:
    # not re-stamped with the rerun's commit and its seconds of wall time
    (tmp_path / "results" / "block_grasp.json").write_text(json.dumps({**resumed, "code": {"commit": "f" * 40}}))
    third = tiny_table(out, results, "--generated=3", "--train_seeds=[7,8]", "--variants=[base,igen]", timeout=180)
    assert third.returncode == 0, third.stderr[-4000:]
    unchanged = json.loads((tmp_path / "results" / "block_grasp.json").read_text())
    assert unchanged["code"] == {"commit": "f" * 40}
    assert unchanged == {**resumed, "code": {"commit": "f" * 40}}


def test_shipped_results_are_what_igen_table_renders_from_their_json():
    """docs/results.md is the page igen-table renders from docs/results/*.json: no hand-edited numbers."""
    from igen_lerobot.experiments.table_report import load_superseded, render_results_page

    docs = Path(__file__).resolve().parents[1] / "docs"
    assert load_superseded(docs / "results"), "the superseded tables stay on the page for the record"
    assert (docs / "results.md").read_text() == render_results_page(docs / "results")


def test_every_shipped_table_names_its_commit_and_config():
    """A published table must say which code and settings made each step (so a fresh run can check it)."""
    from igen_lerobot.experiments.table_report import load_results

    docs = Path(__file__).resolve().parents[1] / "docs"
    for result, _ in load_results(docs / "results"):
        assert provenance_problems(result) == [], result["name"]


def test_provenance_check_names_what_is_missing():
    good = {
        "code": {"commit": "a" * 40, "dirty": False},
        "commands": [{"step": "base", "command": "igen-generate"}, {"step": "train_base_seed0", "command": "x"}],
        "step_code": {"base": {"commit": "a" * 40, "dirty": False}, "train_base_seed0": {"commit": "b" * 40}},
        "config": json.loads(json.dumps(asdict(TableConfig()))),
    }
    assert provenance_problems(good) == []
    no_step = {**good, "step_code": {"base": good["step_code"]["base"]}}
    assert provenance_problems(no_step) == ["step train_base_seed0: no commit recorded"]
    dirty = {**good, "step_code": {**good["step_code"], "base": {"commit": "c" * 40, "dirty": True}}}
    assert provenance_problems(dirty) == ["step base: made with uncommitted changes at cccccccccc"]
    partial = {**good, "config": {"task": "block_grasp"}, "code": {}}
    problems = provenance_problems(partial)
    assert problems[0].startswith("no commit") and "train_seeds" in problems[1]
    # a field that only says where records go may be absent (tables published before it existed);
    # one the config does not have is named
    before_ledgers = {k: v for k, v in good["config"].items() if k != "ledger_dir"}
    assert provenance_problems({**good, "config": before_ledgers}) == []
    unknown = provenance_problems({**good, "config": {**good["config"], "speed": 2}})
    assert unknown == ["config is not a whole TableConfig (unknown ['speed'])"]


def test_every_step_records_the_machine_it_ran_on_and_the_page_says_when_they_differ():
    from igen_lerobot.experiments.provenance import machine_line

    here = code_version()["machine"]
    assert "cores" in here and "torch" in here, here
    one = {"step_code": {"base": code_version(), "train_base_seed0": code_version()}}
    assert machine_line(one) == f"- Machine: every step ran on {here}."
    mixed = {"step_code": {**one["step_code"], "eval_base": {"commit": "a" * 40, "machine": "other CPU"}}}
    line = machine_line(mixed)
    assert line.startswith("- Machine: steps ran on 2 machines") and f"{here}: 2 steps" in line
    assert "other CPU: 1 step;" in line
    older = {"step_code": {"base": {"commit": "a" * 40}}}  # recorded before machines were
    assert machine_line(older) == "- Machine: not recorded (the steps ran before machines were)."


def test_a_training_step_records_the_digest_of_the_data_it_read_and_the_ledger_keeps_it(tmp_path):
    from igen_lerobot.experiments.ledger import Ledger
    from igen_lerobot.experiments.step_runner import StepRunner
    from igen_lerobot.experiments.training_reuse import dataset_digest

    data = tmp_path / "data" / "base"
    (data / "meta").mkdir(parents=True)
    (data / "meta" / "info.json").write_text("{}")
    out, ledger = tmp_path / "table", tmp_path / "ledger"
    runner = StepRunner(out, ledger=Ledger(ledger, out))
    runner.run("train_base_seed1", ["touch", str(tmp_path / "one")], tmp_path / "one", reads=data)
    runner.run("test_base_seed1", ["touch", str(tmp_path / "two")], tmp_path / "two")  # reads no dataset
    recorded = {"train_base_seed1": dataset_digest(data)}
    assert json.loads((out / "step_data.json").read_text()) == recorded
    assert json.loads((ledger / "step_data.json").read_text()) == recorded
    assert runner.record(0.0, tmp_path / "t.json")["step_data"] == recorded
    # the same recipe made again, with other bytes: another digest
    (data / "meta" / "info.json").write_text('{"episodes": 2}')
    (tmp_path / "one").unlink()
    runner.run("train_base_seed1", ["touch", str(tmp_path / "one")], tmp_path / "one", reads=data)
    assert runner.data_digests["train_base_seed1"] != recorded["train_base_seed1"]


def test_a_training_made_before_data_were_recorded_counts_its_data_only_if_they_were_not_made_again(tmp_path):
    from igen_lerobot.experiments.training_reuse import read_as_it_is

    dataset, training = tmp_path / "data" / "base", tmp_path / "train" / "base" / "seed1"
    marker = dataset / "meta" / "igen.json"
    marker.parent.mkdir(parents=True)
    assert not read_as_it_is(dataset, training)  # an incomplete dataset, no training
    marker.write_text("{}")
    assert not read_as_it_is(dataset, training)  # no checkpoint: nothing was read here
    for step, when in (("000001", 2000.0), ("000002", 3000.0)):
        config = training / "checkpoints" / step / "pretrained_model" / "config.json"
        config.parent.mkdir(parents=True)
        config.write_text("{}")
        os.utime(config, (when, when))
    os.utime(marker, (1000.0, 1000.0))
    assert read_as_it_is(dataset, training)  # made before the training's first checkpoint
    os.utime(marker, (2500.0, 2500.0))
    assert not read_as_it_is(dataset, training)  # made again after the training began


def test_a_validation_names_the_data_of_the_weights_it_read_only_when_made_on_the_trainings_machine(tmp_path):
    from igen_lerobot.experiments.table import TableRun, carry_data_record

    run = TableRun(TableConfig(output_dir=str(tmp_path / "t"), variants=["base"]))
    here, there = {"commit": "a" * 40, "machine": "CPU avx2"}, {"commit": "a" * 40, "machine": "CPU avx512f"}
    run.versions.update(train_base_seed1=here, validate_base_seed1=here, train_base_seed2=here)
    run.versions["validate_base_seed2"] = there  # restored from the ledger: another machine's weights
    run.data_digests.update(train_base_seed1="d" * 64, train_base_seed2="e" * 64)
    carry_data_record(run, "validate_base_seed1", "train_base_seed1")
    carry_data_record(run, "validate_base_seed2", "train_base_seed2")
    assert run.data_digests["validate_base_seed1"] == "d" * 64 and "validate_base_seed2" not in run.data_digests
    assert json.loads((tmp_path / "t" / "step_data.json").read_text())["validate_base_seed1"] == "d" * 64
    run.data_digests["train_base_seed1"] = "f" * 64  # trained again later: the validation keeps its own
    carry_data_record(run, "validate_base_seed1", "train_base_seed1")
    assert run.data_digests["validate_base_seed1"] == "d" * 64


def test_the_page_names_rows_whose_seeds_were_trained_on_other_machines_or_other_data():
    from igen_lerobot.experiments.provenance import seeds_made_apart_lines

    def row(variant, seeds):
        return {"variant": variant, "label": variant.title(), "seeds": [{"seed": s} for s in seeds]}

    here, there = {"commit": "a" * 40, "machine": "CPU avx2"}, {"commit": "a" * 40, "machine": "CPU avx512f"}
    result = {
        "rows": [row("base", [1, 2]), row("mg", [1, 2, 3]), row("igen", [1, 2])],
        "step_code": {
            "validate_base_seed1": here, "validate_base_seed2": here,
            "validate_mg_seed1": there, "validate_mg_seed2": there, "validate_mg_seed3": here,
            "validate_igen_seed1": here, "validate_igen_seed2": here,
            "train_base_seed1": there,  # made again on another machine after its weights were evaluated
        },
        "step_data": {"validate_base_seed1": "d" * 64, "validate_base_seed2": "d" * 64,
                      "validate_mg_seed3": "e" * 64, "validate_igen_seed1": "d" * 64,
                      "validate_igen_seed2": "f" * 64, "train_base_seed1": "0" * 64},
    }  # fmt: skip
    lines = seeds_made_apart_lines(result)
    assert lines[0].startswith("- Rows whose seeds were made apart")
    assert lines[1:] == [
        "  - Mg: seeds trained on 2 machines (seeds 1, 2: CPU avx512f; seed 3: CPU avx2), on 2 datasets by "
        f"digest (seeds 1, 2: not recorded; seed 3: {'e' * 12}).",
        "  - Igen: seeds trained on one machine (CPU avx2), on 2 datasets by digest "
        f"(seed 1: {'d' * 12}; seed 2: {'f' * 12}).",
    ]  # Base: one machine, one dataset: not named
    assert seeds_made_apart_lines({**result, "rows": [row("base", [1, 2])]}) == []


def test_the_code_line_counts_steps_per_commit():
    from igen_lerobot.experiments.provenance import code_line

    a, b = {"commit": "a" * 40}, {"commit": "b" * 40}
    assert code_line({"step_code": {"base": a, "eval": a}}) == f"- Code: every step ran at commit {'a' * 10}."
    line = code_line({"step_code": {"base": a, "eval": a, "test": b, "old": None}})
    assert line == (
        f"- Code: steps ran at 3 versions ({'a' * 10}: 2 steps; {'b' * 10}: 1 step; unrecorded: 1 step; "
        "per step in the JSON)."
    )


def test_superseded_tables_render_with_their_curves():
    from igen_lerobot.experiments.table_report import load_superseded, render_page

    docs = Path(__file__).resolve().parents[1] / "docs"
    page = render_page([], load_superseded(docs / "results"))
    assert "## Superseded tables" in page and "### Nut Insertion (full observability on contact), superseded" in page
    # Nut Insertion I-Gen's checkpoints as recorded: 0 / 0 / 78 / 82 / 76
    assert "| I-Gen | 82% (98) | 69–90% | 4000 | 0 / 0 / 78 / 82 / 76 |" in page


def test_a_resumed_table_refuses_settings_that_change_finished_steps(tmp_path):
    from igen_lerobot.experiments.table import check_resumed_config

    out = str(tmp_path / "t")
    check_resumed_config(TableConfig(output_dir=out, variants=["base"]))
    # more rows, more seeds, other worker counts: the finished steps stay valid
    check_resumed_config(TableConfig(output_dir=out, variants=["base", "igen"], train_seeds=[1000, 1001, 1002, 7]))
    check_resumed_config(TableConfig(output_dir=out, workers=1))
    with pytest.raises(ConfigError, match=r"n_trials: 50 -> 20.*new --output_dir"):
        check_resumed_config(TableConfig(output_dir=out, n_trials=20))
    with pytest.raises(ConfigError, match="first seed trains the policy"):
        check_resumed_config(TableConfig(output_dir=out, train_seeds=[5, 1000]))
    check_resumed_config(TableConfig(output_dir=out, variants=["base", "igen"], run_first=["igen"]))
    with pytest.raises(ConfigError, match=r"--run_first must list distinct rows of this table"):
        TableConfig(variants=["base", "igen"], run_first=["mg_demo"])


def test_table_config_refuses_seeds_that_break_the_protocol():

    assert TableConfig().train_seeds == [1000, 1001, 1002]
    assert TableConfig(train_seeds=[5, 6]).train.seed == 5  # the base policy's seed is the first
    with pytest.raises(ConfigError, match="distinct seeds"):
        TableConfig(train_seeds=[1, 1])
    with pytest.raises(ConfigError, match="--val_seed and --test_seed must differ"):
        TableConfig(val_seed=3, test_seed=3)


def test_the_data_scaling_table_is_a_named_table_with_sized_rows(tmp_path):
    """2-Piece Assembly's --table=scaling: I-Gen with 200/1000/5000 generated interventions against 100
    operator interventions, each its own dataset made by its unsized row's command with n episodes
    (same seed: the 100 operator interventions begin with the 10 sources), merged with D alike."""
    from igen_lerobot.experiments.table_steps import needed_parts, variant_label, variant_part

    cfg = TableConfig(task="two_piece_assembly", table="scaling", output_dir=str(tmp_path / "t"))
    assert cfg.variants == ["source_int_100", "igen_200", "igen_1000", "igen_5000"]
    assert cfg.name == "two_piece_assembly_scaling"
    assert cfg.paper_table().success == {"source_int_100": 46, "igen_200": 34, "igen_1000": 70, "igen_5000": 88}
    labels = ["Source Int (100)", "I-Gen (200)", "I-Gen (1000)", "I-Gen (5000)"]
    assert [variant_label(v) for v in cfg.variants] == labels
    assert all(variant_part(v) == v for v in cfg.variants)
    steps = {step.name: step for step in needed_parts(cfg.variants)}
    assert set(steps) == {"source_int", *cfg.variants}  # the generators' source is built too
    data = lambda name: tmp_path / name  # noqa: E731
    command = steps["igen_5000"].command(cfg, data, ["--env.type=two_piece_assembly"], policy="P")
    assert "--num_episodes=5000" in command and f"--source.root={tmp_path / 'source_int'}" in command
    assert "--mode=igen" in command and "--policy.path=P" in command
    assert steps["source_int_100"].command(cfg, data, [], policy="P")[:1] == ["--mode=interventions"]
    assert steps["source_int_100"].seed_offset == steps["source_int"].seed_offset
    assert "--num_episodes=100" in steps["source_int_100"].command(cfg, data, [], policy="P")
    # the main table is unchanged, and a wrong name or row says what exists
    assert TableConfig(task="two_piece_assembly").variants == list(VARIANTS)
    with pytest.raises(ConfigError, match=r"--table='scale'.*\['scaling'\]"):
        TableConfig(task="two_piece_assembly", table="scale")
    with pytest.raises(ConfigError, match="sized rows igen_<n>"):
        TableConfig(task="two_piece_assembly", variants=["igen_0"])
    with pytest.raises(ConfigError, match="--table=scaling is measured with --reveal=full"):
        TableConfig(task="two_piece_assembly", table="scaling", reveal="direction")


def test_a_table_recorded_before_a_setting_existed_resumes_with_its_default(tmp_path):
    """A table_config.json written before --table or --randomize existed has no such key: it is the
    default (a factory's too), not a change."""
    from igen_lerobot.experiments.table import check_resumed_config

    out = tmp_path / "t"
    check_resumed_config(TableConfig(output_dir=str(out), variants=["base"]))
    recorded = json.loads((out / "table_config.json").read_text())
    del recorded["table"], recorded["randomize"], recorded["train"]["threads"]
    (out / "table_config.json").write_text(json.dumps(recorded))
    check_resumed_config(TableConfig(output_dir=str(out), variants=["base"]))
    # a nested key recorded before it existed (train.threads) is the count those tables trained with, 2
    with pytest.raises(ConfigError, match="other settings"):
        check_resumed_config(TableConfig(output_dir=str(out), variants=["base"], train=TrainConfig(threads=1)))


def test_a_table_made_before_the_shared_normaliser_resumes_only_with_each_rows_own(tmp_path):
    """A table_config.json without observation_stats was made with each row's own statistics: resuming
    it under D's would mix two normalisers in one table, so it is refused; "own" resumes it."""
    from igen_lerobot.experiments.table import check_resumed_config
    from igen_lerobot.experiments.table_report import render_markdown

    out = tmp_path / "t"
    check_resumed_config(TableConfig(output_dir=str(out), variants=["base"], observation_stats="own"))
    recorded = json.loads((out / "table_config.json").read_text())
    del recorded["observation_stats"]
    (out / "table_config.json").write_text(json.dumps(recorded))
    with pytest.raises(ConfigError, match="observation_stats: own -> base"):
        check_resumed_config(TableConfig(output_dir=str(out), variants=["base"]))
    check_resumed_config(TableConfig(output_dir=str(out), variants=["base"], observation_stats="own"))
    with pytest.raises(ConfigError, match=r"--observation_stats must be one of \['base', 'own'\]"):
        TableConfig(observation_stats="mine")
    with pytest.raises(ConfigError, match="--train.policy_type=act lacks; pass --observation_stats=own"):
        TableConfig(train=TableTrainConfig(policy_type="act"))
    with pytest.raises(ConfigError, match="--train.policy_type=act lacks"):
        LoopConfig(base_dataset="d", train=TrainConfig(policy_type="act"))
    assert LoopConfig(base_dataset="d", train=TrainConfig(policy_type="act"), observation_stats="own")
    # the published page says which normaliser a table used (one without the key: each row's own)
    docs = Path(__file__).resolve().parents[1] / "docs"
    published = json.loads((docs / "results" / "block_grasp.json").read_text())
    assert "observation_stats" not in published["config"]
    assert "each row's own training data's statistics" in "\n".join(render_markdown(published))


def test_a_table_fixes_its_training_threads_and_a_bad_count_is_refused():
    """Weights differ between torch thread counts, so every table pins one, given or not (draccus builds
    --train.* flags on the class defaults, not the table's)."""
    assert TableConfig().train.threads == 2
    assert TableConfig(train=TrainConfig(steps=5000)).train.threads == 2
    assert TableConfig(train=TrainConfig(threads=1)).train.threads == 1
    assert TrainConfig().threads is None  # igen-loop and plain training keep torch's default
    with pytest.raises(ConfigError, match="train.threads must be >= 1"):
        TrainConfig(threads=0)


def test_a_train_flag_on_the_command_line_keeps_the_tables_other_training_defaults():
    """`igen-table --train.threads=1` must not silently drop the table's checkpoints every 500 steps."""
    from igen_lerobot.scripts.cli import parse_config

    default = parse_config(TableConfig, [])
    assert (default.train.steps, default.train.save_freq, default.train.threads) == (2000, 500, 2)
    one_thread = parse_config(TableConfig, ["--train.threads=1"])
    assert (one_thread.train.steps, one_thread.train.save_freq, one_thread.train.threads) == (2000, 500, 1)
    longer = parse_config(TableConfig, ["--train.steps=5000", "--train.save_freq=1000"])
    assert (longer.train.save_freq, longer.train.threads) == (1000, 2)


def test_the_main_table_across_tasks_has_a_column_per_task_with_all_seven_rows():
    """Tables of the main shape (all seven variants, full observability, not a named table) become one
    combined table, ours (paper) and the interval per cell; other tables stay out of it."""
    from igen_lerobot.experiments.table_report import render_main_table
    from igen_lerobot.experiments.table_steps import variant_label

    def table(task, variants, reveal="full", named=""):
        rows = [
            {"variant": v, "label": variant_label(v), "success_rate": (i + 1) / 10, "ci95": [i / 10, (i + 2) / 10],
             "paper": 10 * i if task != "coffee" else None}
            for i, v in enumerate(variants)
        ]  # fmt: skip
        return {"task": task, "reveal": reveal, "config": {"table": named}, "rows": rows}

    nut, coffee = table("nut_insertion", VARIANTS), table("coffee", VARIANTS)
    others = [
        table("block_grasp", ("base", "source_int", "mg_demo", "igen_no_policy", "igen")),
        table("nut_insertion", VARIANTS, reveal="contact_position"),
        table("two_piece_assembly", ("source_int_100", "igen_200"), named="scaling"),
    ]
    lines = render_main_table([nut, *others, coffee])
    assert lines[5] == "| Variant | Nut Insertion | Coffee |"
    assert lines[7] == "| Base | 10% (0), 0–20% | 10% (–), 0–20% |"
    assert lines[13] == "| I-Gen | 70% (60), 60–80% | 70% (–), 60–80% |" and len(lines) == 15
    assert render_main_table([nut, *others]) == []  # one task: its own table says it all
    assert render_main_table(others) == []


def test_randomised_generation_reaches_the_generators_only_and_names_its_own_table(tmp_path):
    """--randomize: generation as domain randomisation. Every igen-generate step (D and each generated
    row) gets the flags; sources are collected, and every policy evaluated, on the task's own arm;
    the table is saved under its own name, so it never replaces the plain one; bad flags name the fix."""
    from igen_lerobot.experiments.table import plan

    flags = ["--env.randomize.kp_scale=[0.5,1.5]", "--env.randomize.latency=[0,0.04]"]
    cfg = TableConfig(variants=["mg_demo", "igen"], randomize=flags, output_dir=str(tmp_path / "t"), dry_run=True)
    assert cfg.name == "block_grasp_randomized" and TableConfig().name == "block_grasp"
    steps = plan(cfg)
    tools = {s["step"]: s["command"].split()[0] for s in steps}
    randomised = {s["step"] for s in steps if all(f in s["command"].replace("'", "") for f in flags)}
    assert randomised == {s for s, tool in tools.items() if tool == "igen-generate"}
    assert {"base", "mg_test_demos", "igen"} <= randomised  # D, MG Demo's and I-Gen's data
    assert not any("randomize" in s["command"] for s in steps if tools[s["step"]] != "igen-generate")
    assert any(tools[s] == "igen-eval" for s in tools) and any(tools[s] == "igen-collect" for s in tools)
    with pytest.raises(ConfigError, match=r"--env.randomize.\* flags only"):
        TableConfig(randomize=["--env.max_delta=0.1"])
    with pytest.raises(ConfigError, match="no block_grasp arm randomisation; it has .*kp_scale"):
        TableConfig(randomize=["--env.randomize.stiffness=2"])
    with pytest.raises(ConfigError, match=r"latency=\[0.0, 0.5\].*one control period"):
        TableConfig(randomize=["--env.randomize.latency=[0,0.5]"])
    with pytest.raises(ConfigError, match="position-only tasks"):  # the hand's tilt is a 6-DOF task's own action
        TableConfig(task="nut_insertion", randomize=["--env.randomize.hand_tilt_deg=2"])
    # its section says so, and it stays out of the main table across tasks
    from igen_lerobot.experiments import table_report

    result = {"task": "nut_insertion", "reveal": "full", "rows": [{"variant": v} for v in VARIANTS]}
    result["config"] = asdict(TableConfig(task="nut_insertion"))
    assert table_report.is_main_table(result) and not table_report._randomize_line(result["config"])
    result["config"] = asdict(TableConfig(task="nut_insertion", randomize=flags))
    title = table_report._title(result)
    assert title == "Nut Insertion (full observability on contact), generated on randomised arms"
    assert (
        "`--env.randomize.kp_scale=[0.5,1.5] --env.randomize.latency=[0,0.04]`"
        in table_report._randomize_line(result["config"])[0]
    )
    assert not table_report.is_main_table(result)


def test_a_step_is_dirty_for_changed_code_not_for_a_tables_own_docs(tmp_path, monkeypatch):
    """A chain's finished table writes docs/results before the next table starts: that must not mark
    the next table's steps dirty, while any changed code must."""
    from igen_lerobot.experiments import provenance

    def git(*args):
        subprocess.run(["git", "-C", str(tmp_path), *args], check=True, capture_output=True)

    (tmp_path / "docs").mkdir()
    (tmp_path / "docs" / "results.md").write_text("# Results\n")
    (tmp_path / "code.py").write_text("x = 1\n")
    git("init", "-q")
    git("add", ".")
    git("-c", "user.name=t", "-c", "user.email=t@t", "commit", "-qm", "init")
    monkeypatch.setattr(provenance, "REPO_ROOT", tmp_path)
    assert provenance.code_version()["dirty"] is False
    (tmp_path / "docs" / "results.md").write_text("# Results\n\na new table\n")
    assert provenance.code_version()["dirty"] is False
    (tmp_path / "code.py").write_text("x = 2\n")
    assert provenance.code_version()["dirty"] is True


def test_a_run_that_ran_steps_records_itself_and_one_that_ran_none_keeps_the_record(tmp_path):
    from igen_lerobot.experiments.provenance import keep_assembly_record

    recorded = tmp_path / "t.json"
    recorded.write_text(json.dumps({"code": {"commit": "a" * 40}, "wall_time_s": 6000.0}))
    ran = {"code": {"commit": "b" * 40}, "wall_time_s": 300.0}
    keep_assembly_record(ran, recorded, executed=["train_base_seed1000"])
    assert ran == {"code": {"commit": "b" * 40}, "wall_time_s": 300.0}
    idle = {"code": {"commit": "b" * 40}, "wall_time_s": 1.2}
    keep_assembly_record(idle, recorded, executed=[])
    assert idle == {"code": {"commit": "a" * 40}, "wall_time_s": 6000.0}
    first = {"code": {"commit": "b" * 40}, "wall_time_s": 1.2}
    keep_assembly_record(first, tmp_path / "none.json", executed=[])  # nothing recorded yet: its own record
    assert first["code"] == {"commit": "b" * 40}


def test_a_step_stopped_by_sigterm_records_its_leg_and_resumes(tmp_path):
    """A session's end (SIGTERM) must not erase what the stopped leg cost: the table's time says it."""
    import signal
    import threading

    from igen_lerobot.experiments.provenance import provenance_lines
    from igen_lerobot.experiments.step_runner import StepRunner

    runner = StepRunner(tmp_path)
    done = tmp_path / "done"
    stop = threading.Timer(1.0, os.kill, (os.getpid(), signal.SIGTERM))
    stop.start()
    started = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        runner.run("train_x", ["sleep", "30"], done)
    assert time.perf_counter() - started < 10  # the child was stopped with it, not waited for
    assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL  # the handler is the step's only
    stopped = json.loads((tmp_path / "step_interrupted_times.json").read_text())
    assert 0.9 <= stopped["train_x"] <= 10.0 and "train_x" not in runner.timings  # tolerance: the timer's start

    resumed = StepRunner(tmp_path)  # the next session
    resumed.run("train_x", ["touch", str(done)], done)
    assert resumed.interrupted == stopped and resumed.timings["train_x"] < 5.0
    result = {
        "wall_time_s": 60.0,
        "step_times_s": resumed.timings,
        "step_interrupted_s": resumed.interrupted,
        "commands": resumed.commands,
    }
    assert "plus 0.0 min in the legs of 1 step stopped between sessions" in "\n".join(provenance_lines(result))


def test_a_step_that_dies_of_a_crash_signal_runs_once_more_and_its_legs_count(tmp_path):
    """Native code can crash where a rerun succeeds (a segmentation fault in lerobot-train): the step runs
    once more, with what it would run when resumed (worked out again), and both legs count in its time.
    A second crash, or an ordinary failure, fails the step: nothing loops."""
    from igen_lerobot.experiments.step_runner import StepFailedError, StepRunner

    runner = StepRunner(tmp_path)
    legs = tmp_path / "legs"
    # the first leg sleeps 1 s and dies of SIGSEGV; the second finishes
    flaky = f"echo leg >> {legs}; if [ $(wc -l < {legs}) -eq 1 ]; then sleep 1; kill -SEGV $$; fi; touch done"
    worked_out = []

    def resumed() -> list[str]:
        worked_out.append(len(worked_out))
        return ["sh", "-c", f"cd {tmp_path} && {flaky}"]

    runner.run("train_x", ["lerobot-train", "--steps=5"], tmp_path / "done", resumed)
    assert legs.read_text().count("leg") == 2 and worked_out == [0, 1]
    assert runner.timings["train_x"] >= 1.0  # tolerance: the crashed leg's sleep is counted
    assert "train_x: died of SIGSEGV; running it once more" in (tmp_path / "logs" / "train_x.log").read_text()
    assert runner.commands[-1]["command"] == "lerobot-train --steps=5"  # the recorded command is unchanged

    always = tmp_path / "always"
    with pytest.raises(StepFailedError, match=r"exit -6"):
        runner.run("eval_y", ["sh", "-c", f"echo leg >> {always}; kill -ABRT $$"], tmp_path / "never")
    assert always.read_text().count("leg") == 2
    once = tmp_path / "once"
    with pytest.raises(StepFailedError, match=r"exit 3"):
        runner.run("eval_z", ["sh", "-c", f"echo leg >> {once}; exit 3"], tmp_path / "never")
    assert once.read_text().count("leg") == 1


def test_each_step_records_the_code_checked_out_when_it_started(tmp_path, monkeypatch):
    """A commit landed while a table runs is named by the steps started after it, not the earlier ones."""
    from igen_lerobot.experiments import step_runner

    checkouts = iter([{"commit": "a" * 40, "dirty": False}, {"commit": "b" * 40, "dirty": False}])
    monkeypatch.setattr(step_runner, "code_version", lambda: next(checkouts))
    runner = step_runner.StepRunner(tmp_path)  # the table's start: commit a
    runner.run("first", ["touch", str(tmp_path / "first")], tmp_path / "first")  # started at commit b
    assert runner.code["commit"] == "a" * 40
    assert json.loads((tmp_path / "step_commits.json").read_text())["first"]["commit"] == "b" * 40


def test_a_rehearsing_tables_plan_shows_each_sim_to_real_runs_paths_after_its_test(tmp_path):
    """--rehearse: the plan lists each path of a sim-to-real row's run right after that run's test (with the
    last checkpoint, as its test), none for other rows, and writes nothing; other tasks are refused."""
    from igen_lerobot.experiments.config_table import TableRehearsalConfig
    from igen_lerobot.experiments.table import plan

    out = tmp_path / "t"
    cfg = TableConfig(variants=["source_demo", "igen"], train_seeds=[5], rehearse=True, output_dir=str(out))
    cfg.rehearsal.paths = ["franky", "eval"]
    steps = [s["step"] for s in plan(cfg)]
    assert not out.exists()
    assert [s for s in steps if s.startswith("rehearse_")] == ["rehearse_eval_igen_seed5", "rehearse_franky_igen_seed5"]
    assert steps.index("rehearse_eval_igen_seed5") == steps.index("test_igen_seed5") + 1
    franky = next(s["command"] for s in plan(cfg) if s["step"] == "rehearse_franky_igen_seed5")
    assert "--robot.type=franky" in franky and "--trials=20" in franky and "checkpoints/002000" in franky
    with pytest.raises(ConfigError, match="--rehearse=true rehearses --task=block_grasp's main table"):
        TableConfig(task="nut_insertion", rehearse=True)
    with pytest.raises(ConfigError, match=r"--rehearsal.paths must be distinct names among"):
        TableConfig(rehearse=True, rehearsal=TableRehearsalConfig(paths=["eval", "camera"]))
    with pytest.raises(ConfigError, match=r"--rehearsal.trials must be >= 1"):
        TableConfig(rehearsal=TableRehearsalConfig(trials=0))
