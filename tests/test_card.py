"""The dataset card says where the data comes from only as its metadata records it.

The metadata here is what the commands write (``simulation_origin`` in igen-collect and
igen-generate, ``import_origin`` in igen-import, a merge's parts), plus a robot-recorded
``origin`` and a dataset that records none (as ``lerobot-record`` leaves one: no ``origin``).
"""

import pytest

from igen_lerobot.datasets.card import card_fields, card_tags
from igen_lerobot.datasets.meta import SIM_CONTROLLER, import_origin, origin_of, simulation_origin

SIM_CLAIMS = ("Simulation only", "robosuite (MIT)", "OSC_POSE law")


@pytest.fixture(scope="module")
def spec():
    from igen_lerobot.core.env_config import task_config_class

    return task_config_class("block_grasp")().task_spec


def info(robot_type="panda"):
    return {"total_episodes": 3, "total_frames": 300, "fps": 20, "robot_type": robot_type, "features": {}}


def card(spec, meta, robot_type="panda"):
    body = card_fields("unused", spec, info(robot_type), {"task": spec.name, "episode_kinds": {"demo": 3}, **meta})
    return body["dataset_description"]


def source_line(body: str) -> str:
    return next(line for line in body.splitlines() if line.startswith("- **Source**"))


def test_a_simulated_dataset_says_simulator_robot_and_controller(spec):
    meta = {"created_by": "igen-collect", "origin": simulation_origin("panda", "lerobot_env_igen")}
    body = card(spec, meta)
    line = source_line(body)
    assert line.startswith("- **Source**: simulation (simulator: `MuJoCo 3.")
    assert "task package `lerobot_env_igen " in line and "robosuite 1.5" in line
    assert "robot `panda`" in line and SIM_CONTROLLER in line
    assert "Simulation only (MuJoCo 3." in body and "come from robosuite (MIT)" in body
    assert card_tags(spec, meta) == ["synthetic", "simulation", "intervengen", "mimicgen", "interventions",
                                     "imitation-learning", "block_grasp"]  # fmt: skip
    # another task package's controller is not ours to state
    other = simulation_origin("panda", "lerobot_env_elsewhere")
    assert other["controller"] is None and "controller: not recorded" in source_line(card(spec, {"origin": other}))


def test_a_dataset_written_before_origin_was_recorded_says_only_what_its_command_implies(spec):
    body = card(spec, {"created_by": "igen-generate", "mode": "igen"})
    line = source_line(body)
    assert "simulation (simulator: not recorded; task package not recorded); robot not recorded" in line
    assert "controller: not recorded" in line and "OSC_POSE" not in body and "robosuite (MIT)" not in body
    assert "simulation" in card_tags(spec, {"created_by": "igen-generate"})


def test_an_imported_dataset_says_what_its_file_says_and_claims_no_simulation(spec):
    robosuite_args = {
        "env_name": "Square_D0",
        "type": 1,
        "env_kwargs": {"robots": ["Panda"], "controller_configs": {"type": "OSC_POSE", "kp": 150}},
    }
    meta = {"created_by": "igen-import", "origin": import_origin("robomimic", "square.hdf5", robosuite_args)}
    body = card(spec, meta)
    line = source_line(body)
    assert "imported with `igen-import` from `square.hdf5` (robomimic)" in line
    assert "env `Square_D0`, robot `Panda`, controller `OSC_POSE`" in line
    assert "whether it was simulated or recorded on a robot is not known here" in line
    assert not any(claim in body for claim in SIM_CLAIMS)
    assert "its own terms (and its authors') apply" in body and "Imported episodes are what the source file" in body
    assert not {"synthetic", "simulation"} & set(card_tags(spec, meta))
    # a file with no env_args: everything about the recording unknown
    bare = source_line(card(spec, {"created_by": "igen-import", "origin": import_origin("robomimic", "x.hdf5", None)}))
    assert "env not recorded, robot not recorded, controller not recorded" in bare
    # an igen export read back: the exported dataset's origin travels with it
    args = {"env_name": "block_grasp", "type": "igen", "env_kwargs": {"igen": {"created_by": "igen-collect"}}}
    back = source_line(card(spec, {"created_by": "igen-import", "origin": import_origin("robomimic", "b.hdf5", args)}))
    assert "an `igen-export` of a dataset made by `igen-collect` (simulation)" in back


def test_a_robot_recorded_dataset_says_robot_and_never_simulation(spec):
    origin = {"kind": "robot", "robot": "igen_franka", "arm": "franky", "controller": None}
    body = card(spec, {"created_by": "igen-deploy", "origin": origin}, robot_type="igen_franka")
    line = source_line(body)
    assert line == "- **Source**: recorded on a robot: `igen_franka` (arm `franky`); controller: not recorded."
    assert not any(claim in body for claim in SIM_CLAIMS)
    assert "robot type `igen_franka`" in body
    assert not {"synthetic", "simulation"} & set(card_tags(spec, {"origin": origin}))


def test_a_dataset_that_records_no_origin_is_unknown_not_guessed(spec):
    """lerobot-record with --robot.type=igen_franka writes no origin; its arm may be the simulated one or a real one."""
    body = card(spec, {"created_by": "lerobot-record"}, robot_type="igen_franka")
    line = source_line(body)
    assert "not recorded in meta/igen.json (made by `lerobot-record`)" in line
    assert "simulated, imported or recorded on a robot, and with which controller, is unknown" in line
    assert "robot type `igen_franka`" in line
    assert not any(claim in body for claim in SIM_CLAIMS)
    assert "treat its robot, simulator and controller as unknown" in body
    assert not {"synthetic", "simulation"} & set(card_tags(spec, {}))


def test_a_merge_lists_each_parts_source(spec):
    sim = {"created_by": "igen-collect", "origin": simulation_origin("panda", "lerobot_env_igen")}
    imported = {"created_by": "igen-import", "origin": import_origin("robomimic", "a.hdf5", None)}
    parts = [  # as igen-merge records its parts
        {"root": "a", "repeats": 1, "created_by": "igen-collect", "origin": origin_of(sim)},
        {"root": "b", "repeats": 2, "created_by": "igen-import", "origin": origin_of(imported)},
    ]
    meta = {"created_by": "merge", "parts": parts}
    assert origin_of(meta) == {"kind": "merge", "source_kinds": ["import", "simulation"]}
    body = card(spec, meta)
    assert source_line(body).startswith("- **Source**: a merge of 2 datasets (import, simulation); each part's source")
    assert "| `a` | igen-collect | simulation |" in body and "| `b` | igen-import | import |" in body
    assert not {"synthetic", "simulation"} & set(card_tags(spec, meta))
    only_sim = {"created_by": "merge", "parts": parts[:1]}
    assert "simulation" in card_tags(spec, only_sim) and "Simulation only;" in card(spec, only_sim)
