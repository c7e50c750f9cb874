"""A table survives the loss of its machine: the ledger keeps each finished step's small records,
and a run on an empty output folder restores them and makes only what its unfinished rows need."""

import json
import shutil

import pytest

from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.experiments.checkpoint_choice import chosen_checkpoint
from igen_lerobot.experiments.ledger import STEP_RECORDS, Ledger


def test_a_table_on_a_new_machine_restores_its_ledger_and_makes_only_what_unfinished_rows_need(tmp_path, tiny_table):
    out, ledger, results = tmp_path / "table", tmp_path / "ledger", tmp_path / "results.md"
    flags = ("--variants=[base,source_int]", "--train_seeds=[7,8]", "--train.save_freq=1", f"--ledger_dir={ledger}")
    first = tiny_table(out, results, *flags)
    assert first.returncode == 0, first.stderr[-4000:]
    report = json.loads((tmp_path / "results" / "block_grasp.json").read_text())

    # the ledger holds the evaluation reports, the step records, the config, the datasets' sizes and
    # the weights that generation ran: no dataset, no other checkpoint
    kept = {p.relative_to(ledger).as_posix() for p in ledger.rglob("*") if p.is_file()}
    assert {"table_config.json", "dataset_sizes.json", *STEP_RECORDS[:3]} <= kept
    policy = out / "train" / "base" / "seed7" / "checkpoints" / "000002" / "pretrained_model"
    assert {f"data_policy/{p.name}" for p in policy.iterdir()} | {"data_policy/manifest.json"} == {
        k for k in kept if k.startswith("data_policy/")
    }
    assert "data_policy/model.safetensors" in kept
    first_data = json.loads((ledger / "step_data.json").read_text())
    for row in report["rows"]:
        for seed in (7, 8):
            assert f"eval/{row['variant']}/seed{seed}/validation.json" in kept
            step = next(s["chosen_step"] for s in row["seeds"] if s["seed"] == seed)
            assert f"eval/{row['variant']}/seed{seed}/test_step{step}.json" in kept
    assert not any(k.startswith(("data/", "train/", "logs/")) for k in kept), kept
    recorded = json.loads((ledger / "step_times.json").read_text())
    assert recorded == json.loads((out / "step_times.json").read_text())

    # the machine is lost with every row on record: only D is made again (every row trains with it),
    # not the base policy, not the interventions it collects, not their merge
    shutil.rmtree(out)
    again = tiny_table(out, results, *flags)
    assert again.returncode == 0, again.stderr[-4000:]
    assert {p.name for p in (out / "logs").glob("*.log")} == {"source_demos.log", "base.log"}
    assert not (out / "train").exists() and not (out / "data" / "source_int").exists()
    resumed = json.loads((tmp_path / "results" / "block_grasp.json").read_text())
    assert resumed["rows"] == report["rows"]  # the seeds' numbers and the datasets' sizes, read back
    # the protocol is recorded whole, and the steps not made again keep the times that made them
    assert [c["step"] for c in resumed["commands"]] == [c["step"] for c in report["commands"]]
    times = json.loads((out / "step_times.json").read_text())
    for step in ("train_base_seed7", "source_int", "merge_source_int", "train_source_int_seed8", "test_base_seed7"):
        assert times[step] == recorded[step], step
    for step in ("source_demos", "base"):
        assert times[step] != recorded[step], step

    # lost again, and Source Int seed 8's evaluation never reached the ledger: that row's data are made
    # again, by the base policy the ledger kept (not trained again), so they are the data the row's
    # other seeds trained on; what is on record is not made again
    shutil.rmtree(out)
    shutil.rmtree(ledger / "eval" / "source_int" / "seed8")
    # asked for another budget, it refuses before any weights are put in place
    changed = tiny_table(out, results, *flags, "--train.steps=3")
    assert changed.returncode != 0 and "other settings" in changed.stderr, changed.stderr[-2000:]
    assert not (out / "train").exists()
    third = tiny_table(out, results, *flags)
    assert third.returncode == 0, third.stderr[-4000:]
    logs = {p.name for p in (out / "logs").glob("*.log")}
    made = {"source_int", "merge_source_int", "train_source_int_seed8", "validate_source_int_seed8"}
    assert {f"{step}.log" for step in made} <= logs
    not_made = ("train_base_seed7", "train_base_seed8", "validate_base_seed7", "train_source_int_seed7")
    assert not logs & {f"{step}.log" for step in not_made}
    assert (policy / "model.safetensors").read_bytes() == (ledger / "data_policy" / "model.safetensors").read_bytes()
    data = json.loads((out / "step_data.json").read_text())
    assert data["train_source_int_seed8"] == first_data["train_source_int_seed8"]
    times = json.loads((out / "step_times.json").read_text())
    for step in made:
        assert times[step] != recorded[step], step  # this making's time, not the lost one's plus it
    for step in ("train_base_seed7", "validate_source_int_seed7"):
        assert times[step] == recorded[step], step
    assert json.loads((ledger / "step_times.json").read_text()) == times
    resumed = json.loads((tmp_path / "results" / "block_grasp.json").read_text())

    # a rehearsal reads the chosen checkpoints: missing, they are named with the flag that makes them
    # again, which makes every row's data again too (here without any: the datasets are gone as well)
    with pytest.raises(ConfigError, match="--retrain_restored=true"):
        chosen_checkpoint(out, "base", 8)
    shutil.rmtree(out / "data")
    fourth = tiny_table(out, results, *flags, "--retrain_restored=true")
    assert fourth.returncode == 0, fourth.stderr[-4000:]
    assert (out / "data" / "train_source_int" / "meta" / "igen.json").exists()
    step, checkpoint = chosen_checkpoint(out, "base", 8)
    assert (checkpoint / "config.json").exists()
    assert (out / "logs" / "train_base_seed8.log").exists() and not (out / "logs" / "validate_base_seed8.log").exists()
    assert json.loads((tmp_path / "results" / "block_grasp.json").read_text())["rows"] == resumed["rows"]


def test_the_ledger_keeps_only_small_records_and_never_overwrites_a_local_one(tmp_path):
    out, folder = tmp_path / "out", tmp_path / "ledger"
    ledger = Ledger(folder, out)
    report = out / "eval" / "igen" / "seed1" / "validation.json"
    report.parent.mkdir(parents=True)
    report.write_text('{"results": []}')
    dataset_marker = out / "data" / "igen" / "meta" / "igen.json"
    dataset_marker.parent.mkdir(parents=True)
    dataset_marker.write_text("{}")
    checkpoint = out / "train" / "igen" / "seed1" / "config.json"
    checkpoint.parent.mkdir(parents=True)
    checkpoint.write_text("{}")
    (out / "step_times.json").write_text(json.dumps({"igen": 5.0, "validate_igen_seed1": 2.0}))
    ledger.keep(report, dataset_marker, checkpoint, tmp_path / "elsewhere.json")
    ledger.keep_step_records()
    assert sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file()) == [
        "eval/igen/seed1/validation.json",
        "step_times.json",
    ]
    assert not list(folder.rglob(".*.partial"))  # written whole, then renamed

    # a new machine that already made one step again: its own record wins, and only steps on record return
    shutil.rmtree(out)
    (out / "eval" / "igen" / "seed1").mkdir(parents=True)
    (out / "eval" / "igen" / "seed1" / "validation.json").write_text('{"local": true}')
    (out / "step_times.json").write_text(json.dumps({"validate_igen_seed1": 9.0}))
    restored = ledger.restore(on_record=lambda step: step != "igen")
    assert json.loads((out / "step_times.json").read_text()) == {"validate_igen_seed1": 9.0}
    assert json.loads((out / "eval" / "igen" / "seed1" / "validation.json").read_text()) == {"local": True}
    assert restored == []
    assert Ledger(None, out).restore(on_record=lambda step: True) == []


def test_the_kept_data_policy_is_restored_whole_or_not_at_all(tmp_path):
    out, folder = tmp_path / "out", tmp_path / "ledger"
    weights = tmp_path / "trained" / "pretrained_model"
    weights.mkdir(parents=True)
    (weights / "config.json").write_text('{"type": "bc_rnn"}')
    (weights / "model.safetensors").write_bytes(bytes(range(256)) * 4)
    ledger = Ledger(folder, out)
    ledger.keep_policy(weights, "train_base_seed7")
    target = out / "train" / "base" / "seed7" / "checkpoints" / "000002" / "pretrained_model"

    assert not ledger.restore_policy(target, "train_base_seed8")  # another run's weights
    assert Ledger(None, out).restore_policy(target, "train_base_seed7") is False
    kept = folder / "data_policy" / "model.safetensors"
    whole = kept.read_bytes()
    kept.write_bytes(whole[:-1] + b"\x00")  # a flipped byte
    assert not ledger.restore_policy(target, "train_base_seed7") and not target.exists()
    kept.write_bytes(whole)
    (folder / "data_policy" / "manifest.json").unlink()  # cut short before its manifest
    assert not ledger.restore_policy(target, "train_base_seed7") and not target.exists()

    ledger.keep_policy(weights, "train_base_seed7")
    (folder / "data_policy" / ".model.safetensors.partial").write_bytes(b"a copy cut short")  # left by a lost machine
    assert ledger.restore_policy(target, "train_base_seed7")
    assert sorted(p.name for p in target.iterdir()) == ["config.json", "model.safetensors"]
    assert (target / "model.safetensors").read_bytes() == whole
    # the ordinary restore leaves the weights to restore_policy
    ledger.restore(on_record=lambda step: True)
    assert not (out / "data_policy").exists()


def test_a_rehearsing_table_keeps_each_runs_rehearsal_and_trains_again_only_the_unrehearsed(tmp_path, tiny_table):
    """--rehearse: each run is rehearsed as it is tested, its reports kept in the ledger, so on a new machine
    only a run whose rehearsal is not on record (and the data policy, where data still to make need it) is
    trained again, and nothing is rehearsed twice."""
    out, ledger, results = tmp_path / "table", tmp_path / "ledger", tmp_path / "results.md"
    flags = (
        "--variants=[base]",
        "--train_seeds=[7,8]",
        f"--ledger_dir={ledger}",
        "--rehearse=true",
        "--rehearsal.trials=1",
        "--rehearsal.max_steps=5",
        "--rehearsal.paths=[eval,rendered]",
    )
    first = tiny_table(out, results, *flags)
    assert first.returncode == 0, first.stderr[-4000:]
    rehearsal = json.loads((tmp_path / "results" / "block_grasp_rehearsal.json").read_text())
    steps = {f"rehearse_{path}_base_seed{seed}" for path in ("eval", "rendered") for seed in (7, 8)}
    assert set(rehearsal["step_times_s"]) == steps == {c["step"] for c in rehearsal["commands"]}
    assert [(r["variant"], r["path"], r["trials"]) for r in rehearsal["results"]] == [
        ("base", "eval", 2),
        ("base", "rendered", 2),
    ]
    kept = {p.relative_to(ledger).as_posix() for p in ledger.rglob("*.json")}
    for seed in (7, 8):
        assert {f"rehearsal/reports/base/seed{seed}/{path}.json" for path in ("eval", "rendered")} <= kept
    assert "rehearsal/rehearsal_config.json" in kept

    # the machine is lost after seed 8 was tested but before its rehearsal reached the ledger, and the
    # next one holds the checkout elsewhere
    shutil.rmtree(out)
    (ledger / "rehearsal" / "reports" / "base" / "seed8" / "rendered.json").unlink()
    recorded = ledger / "rehearsal" / "rehearsal_config.json"
    recorded.write_text(json.dumps({**json.loads(recorded.read_text()), "table_dir": "/elsewhere/table"}))
    again = tiny_table(out, results, *flags)
    assert again.returncode == 0, again.stderr[-4000:]
    logs = {p.name for p in (out / "logs").glob("*.log")}
    # seed 8 is trained again for its weights, and only its missing path runs; its evaluation stands
    assert {"train_base_seed8.log", "rehearse_rendered_base_seed8.log"} <= logs
    assert not logs & {"validate_base_seed8.log", "test_base_seed8.log", "rehearse_eval_base_seed8.log"}
    # seed 7 is neither trained again (no dataset of a Base-only table runs a policy) nor rehearsed
    assert "train_base_seed7.log" not in logs
    assert not any(name.startswith("rehearse_") and "seed7" in name for name in logs)
    resumed = json.loads((tmp_path / "results" / "block_grasp_rehearsal.json").read_text())
    assert [(r["variant"], r["path"], r["trials"]) for r in resumed["results"]] == [
        ("base", "eval", 2),
        ("base", "rendered", 2),
    ]
    assert resumed["rows"][0]["results"]["eval"] == rehearsal["rows"][0]["results"]["eval"]
    assert (ledger / "rehearsal" / "reports" / "base" / "seed8" / "rendered.json").exists()
