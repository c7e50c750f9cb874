"""robomimic / MimicGen HDF5 in and out: igen-import, igen-export, round trips, and bad files.

The fixtures are written with h5py in exactly the documented layouts (robomimic's
``data/demo_<i>/{actions,rewards,dones,obs/*}`` with ``env_args``; MimicGen's ``datagen_info``):
no public file ships in any package here. Tolerance: 1e-9 for what we store as float64, 1e-6 for
float32 dataset columns.
"""

import contextlib
import io
import json
import sys
from importlib.metadata import entry_points

import h5py
import numpy as np
import pytest
from fake_task import FakeOperator, FakePickPlaceConfig

from igen_lerobot.collection.record import record_demo
from igen_lerobot.core.error_models import NoNoise
from igen_lerobot.core.task import FrameSource
from igen_lerobot.datasets.meta import read_igen_meta
from igen_lerobot.datasets.reader import dataset_spec, load_episodes
from igen_lerobot.datasets.robomimic import IGEN_GROUP
from igen_lerobot.datasets.writer import DatasetBuilder
from igen_lerobot.generation.mimicgen import MimicGenConfig, generate_demo
from igen_lerobot.generation.sources import parse_demos

FAKE = "--env.type=fake_pick_place"


def cli(*cmd):
    """A console script in this process: (exit status, stderr)."""
    main = next(iter(entry_points(group="console_scripts", name=cmd[0]))).load()
    saved, err = sys.argv, io.StringIO()
    sys.argv = list(cmd)
    try:
        with contextlib.redirect_stderr(err):
            main()
        return 0, err.getvalue()
    except SystemExit as exit_:
        return (exit_.code if isinstance(exit_.code, int) else 1), err.getvalue()
    finally:
        sys.argv = saved


@pytest.fixture(scope="module")
def fake_demos():
    config = FakePickPlaceConfig(corruption=NoNoise())
    env = config.make_task_env()
    episodes = [record_demo(env, FakeOperator(), seed, 200) for seed in range(12)]
    assert all(ep.success for ep in episodes)
    return config, episodes


def write_mimicgen_file(path, config, episodes, names, object_keys=None, signal="grasp", drop=None):
    """A MimicGen source file in the documented layout, from episodes (no igen group)."""
    spec, actions = config.task_spec, config.make_action_space()
    object_keys = object_keys or {obj: obj for obj in spec.objects}
    with h5py.File(path, "w") as f:
        data = f.create_group("data")
        data.attrs["env_args"] = json.dumps({"env_name": "PickPlace", "type": 1, "env_kwargs": {}})
        for name, ep in zip(names, episodes, strict=True):
            demo = data.create_group(name)
            n = ep.length
            eef = spec.eef_poses(ep.state)
            demo.attrs["num_samples"] = n
            demo.create_dataset("actions", data=np.random.default_rng(0).uniform(-1, 1, (n, 7)))  # robosuite-scaled
            demo.create_dataset("rewards", data=(np.arange(n) == n - 1).astype(float))
            demo.create_dataset("dones", data=(np.arange(n) == n - 1).astype(int))
            demo.create_dataset("states", data=np.zeros((n, 10)))
            obs = demo.create_group("obs")
            obs.create_dataset("robot0_eef_pos", data=ep.state[:, :3])
            width = ep.state[:, 7]
            obs.create_dataset("robot0_gripper_qpos", data=np.stack([width / 2, -width / 2], axis=1))
            info = demo.create_group("datagen_info")
            info.create_dataset("eef_pose", data=eef)
            info.create_dataset(
                "target_pose", data=np.stack([actions.target_pose(T, a) for T, a in zip(eef, ep.action, strict=True)])
            )
            info.create_dataset("gripper_action", data=np.where(ep.action[:, -1:] > 0, 1.0, -1.0))
            poses = info.create_group("object_poses")
            for obj in spec.objects:
                poses.create_dataset(object_keys[obj], data=spec.object_poses(ep.true_object_pose, obj))
            signals = info.create_group("subtask_term_signals")
            signals.create_dataset(signal, data=(ep.subtask > 0).astype(int))
            if drop:
                del demo[drop]
        f.create_group("mask").create_dataset("train", data=np.array(names, dtype="S"))


def test_a_mimicgen_file_imports_in_demo_number_order_and_seeds_mimicgen(fake_demos, tmp_path):
    config, episodes = fake_demos
    names = [f"demo_{i}" for i in (0, 1, 2, 10, 11, 3)]  # by name, demo_10 would come before demo_2
    keys = {"block": "cube_main", "pad": "target"}
    write_mimicgen_file(tmp_path / "mg.hdf5", config, episodes[:6], names, object_keys=keys, signal="grasped")
    code, err = cli(
        "igen-import",
        "--format=robomimic",
        f"--input={tmp_path / 'mg.hdf5'}",
        FAKE,
        "--object_names={block: cube_main, pad: target}",
        "--subtask_signals=[grasped]",
        f"--dataset.root={tmp_path / 'imported'}",
    )
    assert code == 0, err
    spec = dataset_spec(tmp_path / "imported")
    imported = load_episodes(tmp_path / "imported", spec)
    # the file says only its env's name: robot and controller stay unknown (robosuite files name them)
    assert read_igen_meta(tmp_path / "imported").meta["origin"] == {
        "kind": "import",
        "format": "robomimic",
        "input": str(tmp_path / "mg.hdf5"),
        "env_name": "PickPlace",
        "robot": None,
        "controller": None,
    }
    order = sorted(range(6), key=lambda i: int(names[i].split("_")[1]))  # number order
    assert [ep.seed for ep in imported] == [int(names[i].split("_")[1]) for i in order]
    for ep, source in zip(imported, [episodes[i] for i in order], strict=True):
        assert ep.kind == "demo" and ep.success and not ep.is_intervention.any()
        np.testing.assert_array_equal(ep.subtask, source.subtask)  # cut at each signal's first rise
        np.testing.assert_allclose(ep.state, source.state, atol=1e-6)
        np.testing.assert_allclose(ep.true_object_pose, source.true_object_pose, atol=1e-6)
        # the actions come from datagen_info's target poses through the task's own action space
        np.testing.assert_allclose(ep.action, source.action, atol=1e-6)
        assert np.all(ep.source == FrameSource.OPERATOR)
    # igen-generate takes them as sources: MimicGen through both subtasks
    env = config.make_task_env()
    actions = config.make_action_space()
    library = parse_demos(imported, spec, actions.target_pose, actions.gripper_closed)
    generated = [generate_demo(env, library, MimicGenConfig(), 500 + i, 300) for i in range(5)]
    assert sum(a.kept for a in generated) == 5


def test_ours_to_hdf5_and_back_gives_identical_episodes(fake_demos, tmp_path, source_interventions):
    """A Block Grasp interventions dataset and a two-subtask one round-trip exactly."""
    config, episodes = fake_demos
    builder = DatasetBuilder(tmp_path / "fake", "local/fake", config.task_spec)
    for i, ep in enumerate(episodes[:4]):
        builder.spool.keep(i, ep)
    builder.finalize(None, {"created_by": "test"})
    for root, env in ((source_interventions, "--env.type=block_grasp"), (tmp_path / "fake", FAKE)):
        out = tmp_path / f"{root.name}.hdf5"
        code, err = cli("igen-export", "--format=robomimic", f"--dataset.root={root}", f"--output={out}")
        assert code == 0, err
        with h5py.File(out) as f:  # robomimic's and MimicGen's layouts, for their tools
            assert json.loads(f["data"].attrs["env_args"])["env_name"] == dataset_spec(root).name
            demo = f["data/demo_0"]
            assert {"actions", "rewards", "dones", "obs", "datagen_info", IGEN_GROUP} <= set(demo)
            assert demo["datagen_info/eef_pose"].shape[1:] == (4, 4)
            assert ("states" in demo) == (root != tmp_path / "fake")
            assert f["data"].attrs["total"] == sum(f[f"data/{d}/actions"].shape[0] for d in f["data"])
            check_robomimic_readable(f)
        back = tmp_path / f"{root.name}_back"
        code, err = cli("igen-import", f"--input={out}", env, f"--dataset.root={back}")
        assert code == 0, err
        spec = dataset_spec(root)
        origin = read_igen_meta(back).meta["origin"]
        assert origin["kind"] == "import" and origin["env_name"] == spec.name
        assert origin["exported_from"] == {"created_by": "test"}  # the exported dataset's own provenance
        before, after = load_episodes(root, spec), load_episodes(back, spec)
        assert len(before) == len(after)
        for a, b in zip(before, after, strict=True):
            assert (a.kind, a.seed, a.success) == (b.kind, b.seed, b.success)
            for key in ("state", "env_state", "action", "true_object_pose", "corruption"):
                np.testing.assert_array_equal(getattr(a, key), getattr(b, key))
            for key in ("is_intervention", "source", "subtask"):
                np.testing.assert_array_equal(getattr(a, key), getattr(b, key))
            assert (a.sim_state is None) == (b.sim_state is None) == (root.name.startswith("fake"))
            if a.sim_state is not None:  # the simulator states travel too (robomimic's "states")
                np.testing.assert_array_equal(a.sim_state, b.sim_state)


def robomimic_split(names, ratio, seed=0):
    """robomimic 0.3.0's scripts/split_train_val.py, its split as written there (global seed, string sort)."""
    demos = sorted(names)
    num_val = int(ratio * len(demos))
    mask = np.zeros(len(demos))
    mask[:num_val] = 1.0
    np.random.seed(seed)
    np.random.shuffle(mask)
    mask = mask.astype(int)
    return [demos[i] for i in (1 - mask).nonzero()[0]], [demos[i] for i in mask.nonzero()[0]]


def check_robomimic_readable(f, ratio=0.1, seed=0):
    """What robomimic's SequenceDataset reads by default: next_obs beside obs, and the train/valid filter keys."""
    names = sorted(f["data"])
    for name in names:
        demo = f[f"data/{name}"]
        assert set(demo["next_obs"]) == set(demo["obs"])
        for key in demo["obs"]:
            obs, nxt = demo[f"obs/{key}"][()], demo[f"next_obs/{key}"][()]
            assert nxt.shape == obs.shape and len(obs) == demo.attrs["num_samples"]
            np.testing.assert_array_equal(nxt[:-1], obs[1:])  # the observation after each step
            np.testing.assert_array_equal(nxt[-1], obs[-1])  # the last one repeated, as robomimic's converters do
    train = [n.decode() for n in f["mask/train"][()]]
    valid = [n.decode() for n in f["mask/valid"][()]]
    assert sorted(train + valid) == names and not set(train) & set(valid)
    if len(names) > 1:
        assert valid and train
        if int(ratio * len(names)) >= 1:  # where robomimic's own script gives a validation demo: its very split
            assert (train, valid) == robomimic_split(names, ratio, seed)


def test_the_split_is_robomimics_and_never_leaves_a_side_empty():
    from igen_lerobot.core.exceptions import ConfigError
    from igen_lerobot.datasets.robomimic import split_train_valid

    for n, ratio, seed in [(10, 0.1, 0), (12, 0.1, 0), (25, 0.2, 3), (100, 0.1, 0), (7, 0.5, 1), (3, 0.34, 0)]:
        names = [f"demo_{i}" for i in range(n)]
        assert split_train_valid(names, ratio, seed) == robomimic_split(names, ratio, seed), (n, ratio, seed)
    names = [f"demo_{i}" for i in range(4)]
    train, valid = split_train_valid(names, 0.1)  # robomimic's script: int(0.4) = 0 validation demos
    assert len(valid) == 1 and sorted(train + valid) == names
    assert split_train_valid(["demo_0"], 0.1) == (["demo_0"], [])
    for bad in (0.0, 1.0):
        with pytest.raises(ConfigError, match=r"--valid_fraction=.* leaves mask/(valid|train) empty for 4 demos"):
            split_train_valid(names, bad)


def test_export_split_flags_and_a_one_demo_file(fake_demos, tmp_path, capsys):
    config, episodes = fake_demos
    root = tmp_path / "fake"
    builder = DatasetBuilder(root, "local/fake", config.task_spec)
    for i, ep in enumerate(episodes[:12]):
        builder.spool.keep(i, ep)
    builder.finalize(None, {"created_by": "test"})
    out = tmp_path / "split.hdf5"
    code, err = cli(
        "igen-export", f"--dataset.root={root}", f"--output={out}", "--valid_fraction=0.25", "--split_seed=7"
    )
    assert code == 0, err
    with h5py.File(out) as f:
        check_robomimic_readable(f, ratio=0.25, seed=7)
        split = ([n.decode() for n in f["mask/train"][()]], [n.decode() for n in f["mask/valid"][()]])
    assert split == robomimic_split([f"demo_{i}" for i in range(12)], 0.25, seed=7) and len(split[1]) == 3
    for bad in ("0", "1", "1.5", "-0.1"):
        code, err = cli(
            "igen-export", f"--dataset.root={root}", f"--output={tmp_path / 'bad.hdf5'}", f"--valid_fraction={bad}"
        )
        assert code == 2 and f"--valid_fraction={float(bad)} must be in (0, 1)" in err.strip().splitlines()[-1], err
        assert not (tmp_path / "bad.hdf5").exists() and not (tmp_path / "bad.hdf5.partial").exists()
    one = tmp_path / "one"
    builder = DatasetBuilder(one, "local/one", config.task_spec)
    builder.spool.keep(0, episodes[0])
    builder.finalize(None, {"created_by": "test"})
    capsys.readouterr()
    code, err = cli("igen-export", f"--dataset.root={one}", f"--output={tmp_path / 'one.hdf5'}")
    assert code == 0, err
    assert "the one demo is in mask/train and mask/valid is empty" in capsys.readouterr().out
    with h5py.File(tmp_path / "one.hdf5") as f:
        check_robomimic_readable(f)
        assert [n.decode() for n in f["mask/train"][()]] == ["demo_0"] and len(f["mask/valid"]) == 0
    code, err = cli("igen-import", f"--input={tmp_path / 'one.hdf5'}", FAKE, f"--dataset.root={tmp_path / 'one_back'}")
    assert code == 0, err
    assert len(load_episodes(tmp_path / "one_back", config.task_spec)) == 1


def test_bad_files_are_refused_with_the_reason_and_nothing_is_written(fake_demos, tmp_path):
    config, episodes = fake_demos
    good = tmp_path / "good.hdf5"
    write_mimicgen_file(good, config, episodes[:3], ["demo_0", "demo_1", "demo_2"], signal="grasp")
    truncated = tmp_path / "truncated.hdf5"
    truncated.write_bytes(good.read_bytes()[: len(good.read_bytes()) // 3])
    garbage = tmp_path / "garbage.hdf5"
    garbage.write_bytes(b"\x89HDF\r\n" + bytes(range(256)) * 8)
    no_datagen = tmp_path / "no_datagen.hdf5"
    write_mimicgen_file(no_datagen, config, episodes[:2], ["demo_0", "demo_1"], drop="datagen_info")
    with h5py.File(tmp_path / "not_robomimic.hdf5", "w") as f:
        f.create_dataset("x", data=np.zeros(3))
    sheared = tmp_path / "sheared.hdf5"
    sheared.write_bytes(good.read_bytes())
    with h5py.File(sheared, "r+") as f:  # demo_1's object poses are no rigid transforms
        poses = f["data/demo_1/datagen_info/object_poses/block"][()]
        poses[:, 0, 1] += 0.5
        f["data/demo_1/datagen_info/object_poses/block"][...] = poses
    cases = [
        ([f"--input={truncated}", FAKE], "not a readable HDF5 file|cannot be read"),
        ([f"--input={garbage}", FAKE], "not a readable HDF5 file"),
        ([f"--input={tmp_path / 'nowhere.hdf5'}", FAKE], "does not exist"),
        ([f"--input={tmp_path / 'not_robomimic.hdf5'}", FAKE], "no 'data' group"),
        ([f"--input={no_datagen}", FAKE], "data/demo_0 has no datagen_info"),
        ([f"--input={good}", "--env.type=block_grasp"], r"actions has 7 values per step; task 'block_grasp' takes 4"),
        ([f"--input={good}", FAKE, "--object_names={block: cube}"], r"has no 'cube'.*--object_names"),
        ([f"--input={good}", FAKE, "--subtask_signals=[closed]"], r"no 'closed'.*--subtask_signals"),
        ([f"--input={good}", FAKE, "--format=rlds"], "--format must be one of"),
        (
            [f"--input={sheared}", FAKE],
            r"data/demo_1/datagen_info/object_poses/block holds matrices that are not rigid",
        ),
    ]
    out = tmp_path / "out"
    for args, message in cases:
        code, err = cli("igen-import", *args, f"--dataset.root={out}")
        assert code == 2, (args, err[-1500:])
        import re

        assert re.search(message, err.strip().splitlines()[-1]), (message, err[-800:])
        assert not out.exists() and not out.with_name("out.partial").exists()
    code, err = cli("igen-export", f"--dataset.root={tmp_path / 'missing'}", f"--output={tmp_path / 'x.hdf5'}")
    assert code == 2 and "check --dataset.root" in err
    assert not (tmp_path / "x.hdf5").exists() and not (tmp_path / "x.hdf5.partial").exists()
