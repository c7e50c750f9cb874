r"""HDF5 export/import throughput and Hub push time, on a 1000-episode dataset.

Run:  MUJOCO_GL=egl .venv/bin/python benchmarks/bench_interchange.py --dataset <igen dataset root> [--repeats 3]

1. ``igen-export --format=robomimic`` of the whole dataset (frames/s, file size);
2. ``igen-import`` of that file into a new dataset (frames/s; the round trip is checked equal);
3. ``igen-push`` to the Hub stand-in of tests/hub_server.py on 127.0.0.1 (the real client and
   LeRobot's push code, as a subprocess with HF_ENDPOINT), and reading it back with
   ``LeRobotDataset(repo_id)``: wall time and MB/s.

Export and import run in this process (what the commands call); medians of ``--repeats``.
"""

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))


def folder_mb(root: Path) -> float:
    return sum(p.stat().st_size for p in Path(root).rglob("*") if p.is_file()) / 2**20


def main() -> None:
    from igen_lerobot.datasets.config_dataset import DatasetOutputConfig
    from igen_lerobot.datasets.config_interchange import ExportConfig, ExportSourceConfig, ImportConfig
    from igen_lerobot.datasets.interchange import export_dataset, import_dataset
    from igen_lerobot.datasets.reader import dataset_spec, load_episodes

    parser = argparse.ArgumentParser()
    parser.add_argument("--dataset", required=True)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    root = Path(args.dataset)
    spec = dataset_spec(root)
    work = Path(tempfile.mkdtemp())
    exports, imports = [], []
    for r in range(args.repeats):
        out = work / f"export_{r}.hdf5"
        t0 = time.perf_counter()
        done = export_dataset(ExportConfig(dataset=ExportSourceConfig(root=str(root)), output=str(out)))
        exports.append((done["frames"] / (time.perf_counter() - t0), done))
        t0 = time.perf_counter()
        back = import_dataset(
            ImportConfig(input=str(out), task=spec.name, dataset=DatasetOutputConfig(root=str(work / f"back_{r}")))
        )
        imports.append(back["frames"] / (time.perf_counter() - t0))
    before, after = load_episodes(root, spec), load_episodes(work / "back_0", spec)
    identical = len(before) == len(after) and all(
        np.array_equal(a.action, b.action) and np.array_equal(a.env_state, b.env_state)
        for a, b in zip(before, after, strict=True)
    )

    from hub_server import FakeHub

    hub = FakeHub({"hf_bench": "bench"})
    url = hub.start()
    env = {**os.environ, "HF_ENDPOINT": url, "HF_TOKEN": "hf_bench", "HF_HUB_OFFLINE": "0"}
    env["HF_HOME"] = str(work / "hf_home")
    bin_dir = Path(sys.executable).parent
    t0 = time.perf_counter()
    push = subprocess.run(
        [str(bin_dir / "igen-push"), f"--dataset.root={root}", "--dataset.repo_id=bench/data"],
        env=env,
        capture_output=True,
        text=True,
    )
    push_s = time.perf_counter() - t0
    read = "import sys; from lerobot.datasets.lerobot_dataset import LeRobotDataset; "
    read += "LeRobotDataset('bench/data', root=sys.argv[1])"
    t0 = time.perf_counter()
    download = subprocess.run(
        [str(bin_dir / "python"), "-c", read, str(work / "download")], env=env, capture_output=True, text=True
    )
    download_s = time.perf_counter() - t0
    hub.stop()
    if push.returncode or download.returncode:
        raise SystemExit(f"push/download failed:\n{push.stderr[-2000:]}\n{download.stderr[-2000:]}")
    size = folder_mb(root)
    result = {
        "dataset": str(root),
        "episodes": exports[0][1]["episodes"],
        "frames": exports[0][1]["frames"],
        "dataset_mb": size,
        "hdf5_mb": (work / "export_0.hdf5").stat().st_size / 2**20,
        "export_frames_per_s": float(np.median([e[0] for e in exports])),
        "import_frames_per_s": float(np.median(imports)),
        "round_trip_identical": identical,
        "push_s_including_startup": push_s,
        "push_mb_per_s": size / push_s,
        "download_s_including_startup": download_s,
        "unknown_requests": hub.unknown,
    }
    shutil.rmtree(work)
    print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
