"""A table takes a sibling table's training when the data and command are the same, and only then."""

import json
import os
from pathlib import Path

from igen_lerobot.experiments.training_reuse import KEY_FILE, dataset_digest, find_identical_training, training_key

ONE_RUN = ("--variants=[base]", "--train_seeds=[7]", "--train.save_freq=1")


def test_a_sibling_tables_identical_training_is_linked_in_and_evaluated_anew(tmp_path, tiny_table):
    tables, results = tmp_path / "tables", tmp_path / "results.md"
    first = tiny_table(tables / "first", results, *ONE_RUN)
    assert first.returncode == 0, first.stderr[-4000:]
    made = tables / "first" / "train" / "base" / "seed7"
    assert json.loads((made / KEY_FILE).read_text()).keys() == {"key"}

    second = tiny_table(tables / "second", results, *ONE_RUN)
    assert second.returncode == 0, second.stderr[-4000:]
    taken = tables / "second" / "train" / "base" / "seed7"
    assert json.loads((tables / "second" / "step_reused.json").read_text()) == {"train_base_seed7": str(made)}
    assert json.loads((taken / KEY_FILE).read_text()) == {
        **json.loads((made / KEY_FILE).read_text()),
        "reused_from": str(made),
    }
    # every checkpoint is the same file (hard links), so the weights are those the first table tested
    for step in ("000001", "000002"):
        weights = Path("checkpoints", step, "pretrained_model", "model.safetensors")
        assert os.stat(made / weights).st_ino == os.stat(taken / weights).st_ino
    # its cost and commit are the training's; its evaluations are this table's own
    for records in ("step_times.json", "step_cpu_times.json", "step_commits.json"):
        made_records = json.loads((tables / "first" / records).read_text())
        taken_records = json.loads((tables / "second" / records).read_text())
        assert taken_records["train_base_seed7"] == made_records["train_base_seed7"]
        assert {"validate_base_seed7", "test_base_seed7"} <= taken_records.keys()
    # both read the same data, and each says so by its digest
    digest = dataset_digest(tables / "first" / "data" / "base")
    read = {"train_base_seed7": digest, "validate_base_seed7": digest}
    assert json.loads((tables / "first" / "step_data.json").read_text()) == read
    assert json.loads((tables / "second" / "step_data.json").read_text()) == read
    report = json.loads((tmp_path / "results" / "block_grasp.json").read_text())
    assert report["step_reused"] == {"train_base_seed7": str(made)} and report["step_data"] == read
    assert "- Reused: 1 training taken from first" in results.read_text()

    # another command or other data is another key (test_the_key_is_..., below): nothing is taken for it
    key = json.loads((made / KEY_FILE).read_text())["key"]
    elsewhere = tables / "third" / "train" / "base" / "seed7"
    assert find_identical_training(tables, key, elsewhere, 2) == made
    assert find_identical_training(tables, "another key", elsewhere, 2) is None

    # a table that is told not to reuse trains its own
    third = tiny_table(tables / "third", results, *ONE_RUN, "--reuse_trainings=false")
    assert third.returncode == 0, third.stderr[-4000:]
    assert json.loads((tables / "third" / "step_reused.json").read_text()) == {}
    made_again = tables / "third" / "train" / "base" / "seed7" / "checkpoints" / "000002"
    assert (
        os.stat(made_again / "pretrained_model" / "model.safetensors").st_ino
        != os.stat(made / "checkpoints" / "000002" / "pretrained_model" / "model.safetensors").st_ino
    )


def _dataset(root: Path, data: bytes, stats: dict, meta: dict) -> Path:
    (root / "data" / "chunk-000").mkdir(parents=True)
    (root / "meta").mkdir()
    (root / "data" / "chunk-000" / "file-000.parquet").write_bytes(data)
    (root / "meta" / "stats.json").write_text(json.dumps(stats))
    (root / "meta" / "igen.json").write_text(json.dumps(meta))
    return root


def test_the_key_is_the_data_and_the_command_not_the_paths_or_provenance(tmp_path):
    stats = {"action": {"mean": [0.1, 0.2]}, "observation.state": {"std": [1.0]}}
    a = _dataset(tmp_path / "a" / "data" / "train_base", b"rows", stats, {"reveal": "full"})
    # the same numbers written in another key order, another provenance, another folder: the same data
    reordered = dict(reversed(stats.items()))
    b = _dataset(tmp_path / "b" / "data" / "train_base", b"rows", reordered, {"reveal": "direction"})
    changed = _dataset(tmp_path / "c" / "data" / "train_base", b"rowz", stats, {"reveal": "full"})
    assert dataset_digest(a) == dataset_digest(b) != dataset_digest(changed)

    def key(dataset: Path, out: Path, steps: int = 5000, threads: str = "1") -> str:
        command = [
            "/venv/bin/lerobot-train",
            f"--dataset.repo_id=local/{dataset.name}",
            f"--dataset.root={dataset}",
            f"--output_dir={out}",
            f"--steps={steps}",
        ]
        return training_key(command, {"OMP_NUM_THREADS": threads}, dataset, out)

    same = key(a, tmp_path / "a" / "train" / "base" / "seed7")
    assert key(b, tmp_path / "b" / "train" / "base" / "seed7") == same
    assert key(changed, tmp_path / "c" / "train" / "base" / "seed7") != same
    assert key(a, tmp_path / "a" / "train" / "base" / "seed7", steps=6000) != same
    assert key(a, tmp_path / "a" / "train" / "base" / "seed7", threads="2") != same


def test_a_normalising_dataset_counts_by_its_statistics_not_its_folder(tmp_path):
    """Two tables' base datasets D hold the same statistics in different folders: a row normalised with
    either trains the same weights (so the partial table can take the full table's MG Demo); other
    statistics, or none, are another training."""
    stats = {"observation.state": {"mean": [0.5], "std": [0.1]}}
    data = _dataset(tmp_path / "data" / "train_mg_demo", b"rows", stats, {})
    full_d = _dataset(tmp_path / "full" / "data" / "base", b"d", stats, {"reveal": "full"})
    partial_d = _dataset(tmp_path / "partial" / "data" / "base", b"d", dict(reversed(stats.items())), {})
    wider = {"observation.state": {"mean": [0.5], "std": [0.2]}}
    other_d = _dataset(tmp_path / "other" / "data" / "base", b"d", wider, {})
    out = tmp_path / "train" / "mg_demo" / "seed7"

    def key(*normaliser: Path) -> str:
        command = ["/venv/bin/lerobot-train", f"--dataset.root={data}", f"--output_dir={out}"]
        command += [f"--policy.observation_stats={root}" for root in normaliser]
        return training_key(command, {}, data, out)

    assert key(full_d) == key(partial_d)
    assert key(full_d) != key(other_d)
    assert key(full_d) != key()
