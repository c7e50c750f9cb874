"""Tables with evaluation columns and rows of their own (Nut-and-Peg's, one column per geometry).

The whole table takes hours of CPU; here its declaration is checked, its plan (every command
igen-table would run, from the same code as a run) and the rendering of a synthetic result.
"""

import pytest

from igen_lerobot.core.belief import Reveal
from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.core.paper import DerivedVariant, PaperTable
from igen_lerobot.experiments.config_table import TableConfig
from igen_lerobot.experiments.table import plan, summarise_row
from igen_lerobot.experiments.table_report import render_markdown

COLUMNS = {
    "geometry 1": ("--env.geometry=1",),
    "geometry 2": ("--env.geometry=2",),
    "mixture": ("--env.geometry=mixture",),
}
MG2 = DerivedVariant("mg_demo", "MG Demo (geometry 2)", ("--env.geometry=2",), with_base=False)


def test_a_paper_table_with_columns_is_checked_and_names_the_fix():
    table = PaperTable(
        Reveal.NONE, rows=("base", "mg2"), derived={"mg2": MG2}, columns=COLUMNS, choose_on="mixture",
        success={"base": (100, 0, 50), "mg2": (0, 100, 50)},
    )  # fmt: skip
    assert table.paper_success("mg2", "geometry 2") == 100 and table.paper_success("mg2", "mixture") == 50
    assert table.paper_success("mg2") is None and table.paper_success("igen", "mixture") is None
    assert MG2.data_tag == "env_geometry_2"
    one_column = PaperTable(Reveal.FULL, rows=("base", "igen"), success={"igen": 98})  # the other tasks' form
    assert one_column.paper_success("igen") == 98
    with pytest.raises(ValueError, match=r"one per column \['geometry 1', 'geometry 2', 'mixture'\]"):
        PaperTable(Reveal.NONE, rows=("base",), columns=COLUMNS, choose_on="mixture", success={"base": (100, 0)})
    with pytest.raises(ValueError, match="choose_on='': name the column"):
        PaperTable(Reveal.NONE, rows=("base",), columns=COLUMNS)
    with pytest.raises(ValueError, match="not one number each; declare the table's columns"):
        PaperTable(Reveal.NONE, rows=("base",), success={"base": (100, 0, 50)})
    with pytest.raises(ValueError, match=r"not env flags; write each as --env.<field>=<value>"):
        PaperTable(Reveal.NONE, rows=("base",), columns={"g1": ("geometry=1",)}, choose_on="g1")
    with pytest.raises(ValueError, match="not igen-table variants.*derived rows"):
        PaperTable(Reveal.NONE, rows=("base", "mg2"))
    with pytest.raises(ValueError, match="reuse igen-table variant names"):
        PaperTable(Reveal.NONE, rows=("mg_demo",), derived={"mg_demo": MG2})
    with pytest.raises(ValueError, match="base adds no dataset"):
        DerivedVariant("base", "Base (geometry 2)", ("--env.geometry=2",))


def test_nut_and_peg_plans_its_datasets_and_a_test_per_geometry(tmp_path):
    cfg = TableConfig(task="nut_and_peg", train_seeds=[7], output_dir=str(tmp_path))
    assert cfg.variants == ["base", "source_int", "mg_demo_geometry_2", "base_and_mg_demo_geometry_2", "igen"]
    commands = {c["step"]: c["command"] for c in plan(cfg)}
    data = tmp_path / "data"
    # D, the interventions and I-Gen: the task's own env (the mixture), no geometry forced
    for step in ("source_demos", "base", "source_int", "igen"):
        assert "--env.geometry" not in commands[step], step
    # MG Demo: test-time demonstrations on geometry 2 (the robot observes the handle on the wrong side, the
    # operator grasps the real one), then MimicGen from them on geometry 2; made once for both rows
    demos, mg = commands["test_demos_env_geometry_2"], commands["mg_test_demos_env_geometry_2"]
    assert demos.startswith("igen-collect --mode=demos --demo_observation=corrupted --env.type=nut_and_peg")
    assert "--env.geometry=2" in demos and "--env.geometry=2" in mg
    assert "--mode=mimicgen --demo_observation=corrupted" in mg
    assert f"--source.root={data / 'test_demos_env_geometry_2'}" in mg
    assert "test_demos" not in commands and "mg_test_demos" not in commands  # the mixture's are not built
    # MG Demo trains on those alone, Base + MG Demo on D plus them
    assert "merge_mg_demo_geometry_2" not in commands
    assert f"--dataset.root={data / 'mg_test_demos_env_geometry_2'} " in commands["train_mg_demo_geometry_2_seed7"]
    merge = commands["merge_base_and_mg_demo_geometry_2"]
    assert f"--inputs=[{data / 'base'},{data / 'mg_test_demos_env_geometry_2'}]" in merge
    # each seed's checkpoint chosen on the mixture's validation trials, then tested on each geometry
    for variant in cfg.variants:
        assert "--env.geometry=mixture --train_dir=" in commands[f"validate_{variant}_seed7"]
        for column, flag in (("geometry_1", "1"), ("geometry_2", "2"), ("mixture", "mixture")):
            test = commands[f"test_{variant}_seed7_{column}"]
            assert f"--env.geometry={flag} --policy.path=" in test and "--n_trials=50 --seed=2000003" in test
            assert test.endswith(f"test_{column}_step2000.json")
    assert not (tmp_path / "table_config.json").exists()  # a plan runs and writes nothing


def test_other_tasks_plan_as_before_and_refuse_nut_and_peg_rows(tmp_path):
    cfg = TableConfig(task="block_grasp", train_seeds=[7], variants=["base", "mg_demo"], output_dir=str(tmp_path))
    commands = {c["step"]: c["command"] for c in plan(cfg)}
    assert {"test_base_seed7", "test_mg_demo_seed7", "test_demos", "mg_test_demos"} <= set(commands)
    assert not any("--env.geometry" in c for c in commands.values())
    assert commands["test_base_seed7"].endswith("test_step2000.json")
    with pytest.raises(ConfigError, match="--variants must be a non-empty list"):
        TableConfig(task="block_grasp", variants=["mg_demo_geometry_2"])


def _seed(seed, rates):
    tests = {
        c: {"successes": r, "trials": 50, "success_rate": r / 50, "ci95": [0, 1]}
        for c, r in zip(COLUMNS, rates, strict=True)
    }
    return {"seed": seed, "chosen_step": 2000, "validation_rate": 0.9, "validation": {2000: 0.9},
            "test": tests["mixture"], "columns": tests}  # fmt: skip


def test_a_table_with_columns_renders_a_cell_per_column_with_the_papers_number():
    dataset = {"episodes": 1010, "frames": 200000}
    row = summarise_row(
        "igen", [_seed(7, (46, 44, 45)), _seed(8, (48, 42, 45))], 90, dataset, label="I-Gen",
        paper_columns={"geometry 1": 92, "geometry 2": 88, "mixture": 90},
    )  # fmt: skip
    columns = row["columns"]
    assert columns["geometry 1"]["success_rate"] == pytest.approx(0.94) and columns["mixture"]["trials"] == 100
    assert row["success_rate"] == columns["mixture"]["success_rate"]  # the row's own numbers: the choice column's
    mg = summarise_row("mg_demo_geometry_2", [_seed(7, (0, 50, 25))], 50, dataset, label="MG Demo (geometry 2)",
                       paper_columns={"geometry 1": 0, "geometry 2": 100, "mixture": 50})  # fmt: skip
    mg["without_base"] = True  # as igen-table marks it
    cfg = TableConfig(task="nut_and_peg", train_seeds=[7, 8])
    result = {
        "task": "nut_and_peg", "reveal": "none", "columns": COLUMNS, "choose_on": "mixture",
        "config": {**vars(cfg), "train": vars(cfg.train)}, "rows": [mg, row], "commands": [],
        "step_code": {}, "wall_time_s": 60.0, "step_times_s": {},
    }  # fmt: skip
    lines = render_markdown(result)
    assert lines[0] == "## Nut And Peg (nothing revealed)"
    assert lines[2].startswith("| Variant | geometry 1 | geometry 2 | mixture | test rate per seed")
    assert "| validation (mixture), best checkpoint |" in lines[2]
    assert lines[4].startswith(
        "| MG Demo (geometry 2) | 0% (0), 0–7% | 100% (100), 93–100% | 50% (50), 37–63% | 0 ; 100 ; 50 |"
    )
    assert lines[5].startswith(
        "| I-Gen | 94% (92), 88–97% | 86% (88), 78–91% | 90% (90), 83–94% | 92 / 96 ; 88 / 84 ; 90 / 90 |"
    )
    assert any(line.startswith("- Columns: every chosen checkpoint is tested in each column") for line in lines)
    assert "geometry 2: `--env.geometry=2`" in "\n".join(lines)
    assert "- Trained on their own data alone, not D plus it: MG Demo (geometry 2)." in lines
