"""Algorithm 1's outer loop end to end: k=2 iterations of train -> collect -> generate -> aggregate,
with real lerobot-train runs (a few steps each), then a resume that redoes nothing."""

import json
import os
import subprocess
import sys
from pathlib import Path

from igen_lerobot.datasets.reader import load_episodes, read_igen_meta


def test_two_iterations_grow_the_dataset_and_resume_without_redoing(source_demos, tmp_path):
    from lerobot_env_igen.block_grasp.spec import SPEC

    out = tmp_path / "loop"
    cmd = [
        str(Path(sys.executable).parent / "igen-loop"),
        "--task=block_grasp",
        f"--base_dataset={source_demos}",
        "--iterations=2",
        "--interventions=2",
        "--generated=2",
        "--train.steps=3",
        "--train.batch_size=8",
        "--train.num_workers=0",
        "--train_final=false",
        f"--output_dir={out}",
    ]
    env = {**os.environ, "MUJOCO_GL": "egl", "HF_HUB_OFFLINE": "1"}
    first = subprocess.run(cmd, capture_output=True, text=True, timeout=300, env=env)
    assert first.returncode == 0, first.stderr[-3000:]
    produced = json.loads(first.stdout[first.stdout.index("{") :])
    base = len(load_episodes(source_demos, SPEC))
    sizes = []
    for it in produced["iterations"]:
        # the policy of each iteration was trained by lerobot-train on that D
        assert (Path(it["policy"]) / "model.safetensors").exists()
        sources = load_episodes(it["interventions"], SPEC)
        assert len(sources) == 2 and all(e.is_intervention.any() for e in sources)
        meta = read_igen_meta(Path(it["interventions"])).meta
        assert meta["policy"] == it["policy"], "interventions were collected on the trained policy"
        generated = read_igen_meta(Path(it["generated"])).meta
        assert generated["policy"] == it["policy"] and generated["mode"] == "igen"
        sizes.append(len(load_episodes(it["dataset"], SPEC)))
    assert sizes == [base + 2, base + 4]  # D grows by n generated interventions per iteration
    # every policy reads its inputs with the base dataset's statistics: the first trains on it, the
    # later ones on D + generated are given it (--observation_stats=base, the default)
    given = [json.loads((Path(it["policy"]) / "config.json").read_text()) for it in produced["iterations"]]
    assert given[0]["observation_stats"] is None and given[1]["observation_stats"] == str(source_demos)

    stamp = (Path(produced["iterations"][0]["policy"]) / "model.safetensors").stat().st_mtime
    again = subprocess.run(cmd, capture_output=True, text=True, timeout=300, env=env)
    assert again.returncode == 0, again.stderr[-3000:]
    assert (Path(produced["iterations"][0]["policy"]) / "model.safetensors").stat().st_mtime == stamp
    assert "training already done" in again.stderr
