r"""Camera streams: render throughput, what recording simulator states costs, generation with cameras on/off,
dataset sizes with and without video.

Run:  MUJOCO_GL=egl .venv/bin/python benchmarks/bench_render.py --task=block_grasp \
          --sources outputs/datasets/block_grasp_source_demos [--episodes 20] [--out bench_render.json]

1. render throughput per core (pinned to CPU 0): restore a recorded state + render agentview and
   wrist, at 84, 128 and 256 px (frames/s; one frame = both cameras), no encoding;
2. ``igen-render`` end to end (restore, render, LeRobot's AV1 encoding, aggregation) at 128 px
   with 1 and 2 workers, frames/s of wall time;
3. what state-only generation pays for the states: the ``sim_state`` call per step, env steps/s of
   the scripted operator with and without it (same code, the call switched off; medians of 10
   alternating rounds), and the dataset write with and without the column (medians of 6);
4. ``igen-generate --mode=mimicgen`` of N episodes with 2 workers, with ``--render.cameras`` off
   and on (agentview + wrist, 128 px): wall time and the slowdown;
5. dataset size per 1000 episodes: state only, and with two 84/128/256 px camera streams.
"""

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")
os.environ.setdefault("OMP_NUM_THREADS", "1")

BIN = Path(sys.executable).parent
CAMERAS = ["agentview", "wrist"]


def folder_bytes(root: Path) -> int:
    return sum(p.stat().st_size for p in Path(root).rglob("*") if p.is_file())


def render_rate(env, states, size: int) -> float:
    from igen_lerobot.core.cameras import render_images

    env.restore_sim_state(states[0])
    render_images(env, CAMERAS, size)  # the renderer is built once per size
    start = time.perf_counter()
    for state in states:
        env.restore_sim_state(state)
        render_images(env, CAMERAS, size)
    return len(states) / (time.perf_counter() - start)


def state_cost(env_cfg, episodes: int, rounds: int = 10) -> dict:
    """What recording the state costs per step: the call itself, and recording demos with and without it.

    The A/B runs alternate (order flipped every round) and report medians: this VM's speed drifts by
    +-20% from minute to minute, more than the effect measured.
    """
    import dataclasses

    from igen_lerobot.collection.record import record_demo
    from igen_lerobot.core.error_models import NoNoise
    from igen_lerobot.core.seeding import episode_seed

    env_cfg = dataclasses.replace(env_cfg, corruption=NoNoise())
    env, operator = env_cfg.make_task_env(), env_cfg.make_scripted_operator()
    with_state = env.sim_state
    env.reset(0)
    start = time.perf_counter()
    for _ in range(20000):
        with_state()
    call_us = 1e6 * (time.perf_counter() - start) / 20000
    rates: dict[str, list[float]] = {"with_state": [], "without_state": []}
    for r in range(rounds):
        for label in ("with_state", "without_state")[:: 1 if r % 2 == 0 else -1]:
            env.sim_state = with_state if label == "with_state" else (lambda: None)
            steps, start = 0, time.perf_counter()
            for i in range(episodes):
                steps += record_demo(env, operator, episode_seed(3, i), env_cfg.episode_length).length
            rates[label].append(steps / (time.perf_counter() - start))
    env.close()
    out = {f"record_steps_per_s_{k}": statistics.median(v) for k, v in rates.items()}
    out["record_slowdown"] = 1 - out["record_steps_per_s_with_state"] / out["record_steps_per_s_without_state"]
    out["sim_state_call_us"] = call_us
    out["sim_state_call_share_of_a_step"] = call_us * 1e-6 * out["record_steps_per_s_without_state"]
    return out


def write_cost(spec, episodes) -> dict:
    """Dataset write frames/s with and without the sim_state column, alternating, medians of 6."""
    import copy

    from igen_lerobot.datasets.writer import write_lerobot_dataset

    bare = [copy.copy(e) for e in episodes]
    for e in bare:
        e.sim_state = None
    frames = sum(e.length for e in episodes)
    rates: dict[str, list[float]] = {"with_state": [], "without_state": []}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(6):
            pairs = (("with_state", episodes), ("without_state", bare))
            for label, eps in pairs[:: 1 if r % 2 == 0 else -1]:
                start = time.perf_counter()
                write_lerobot_dataset(Path(tmp) / f"{label}{r}", f"local/{label}", spec, eps, len(eps), {})
                rates[label].append(frames / (time.perf_counter() - start))
    out = {f"write_frames_per_s_{k}": statistics.median(v) for k, v in rates.items()}
    out["write_slowdown"] = 1 - out["write_frames_per_s_with_state"] / out["write_frames_per_s_without_state"]
    return out


def timed(command: list[str]) -> float:
    start = time.perf_counter()
    result = subprocess.run(command, capture_output=True, text=True, check=False)
    if result.returncode != 0:
        raise SystemExit(f"{command[0]} failed:\n{result.stderr[-3000:]}")
    return time.perf_counter() - start


def main() -> None:
    from lerobot.datasets.dataset_metadata import LeRobotDatasetMetadata

    from igen_lerobot.core.env_config import task_config_class
    from igen_lerobot.datasets.reader import dataset_spec, load_episodes

    parser = argparse.ArgumentParser()
    parser.add_argument("--task", default="block_grasp")
    parser.add_argument("--sources", required=True, help="an igen-collect demos dataset (with simulator states)")
    parser.add_argument("--episodes", type=int, default=20)
    parser.add_argument("--out", default=None)
    parser.add_argument("--state-cost-only", action="store_true", help="only step 3, on the --sources dataset")
    args = parser.parse_args()
    env_cfg = task_config_class(args.task)()
    result: dict = {"task": args.task, "episodes": args.episodes}
    if args.state_cost_only:
        os.sched_setaffinity(0, {0})
        spec = dataset_spec(Path(args.sources))
        result.update(state_cost(env_cfg, 4))
        result.update(write_cost(spec, load_episodes(Path(args.sources), spec) * 10))
        print(json.dumps(result, indent=2))
        return
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        # the base data: generated MimicGen demos, state only, then with cameras on
        generate = [
            str(BIN / "igen-generate"),
            "--mode=mimicgen",
            f"--task={args.task}",
            f"--source.root={args.sources}",
            f"--num_episodes={args.episodes}",
            "--workers=2",
        ]
        result["generate_s_cameras_off"] = timed([*generate, f"--dataset.root={tmp / 'off'}"])
        result["generate_s_cameras_on"] = timed(
            [*generate, f"--dataset.root={tmp / 'on'}", f"--render.cameras=[{','.join(CAMERAS)}]", "--render.size=128"]
        )
        result["generate_slowdown_with_cameras"] = result["generate_s_cameras_on"] / result["generate_s_cameras_off"]
        frames = LeRobotDatasetMetadata("local/off", root=tmp / "off").total_frames
        result["frames"] = frames
        per_1000 = 1000 / args.episodes / 2**20
        result["mb_per_1000_episodes_state_only"] = folder_bytes(tmp / "off") * per_1000

        # igen-render end to end, 1 and 2 workers; sizes per resolution
        for workers in (1, 2):
            seconds = timed(
                [
                    str(BIN / "igen-render"),
                    f"--dataset.root={tmp / 'off'}",
                    f"--cameras=[{','.join(CAMERAS)}]",
                    "--size=128",
                    f"--num_workers={workers}",
                    f"--output.root={tmp / f'r128_{workers}'}",
                ]
            )
            result[f"igen_render_128px_frames_per_s_{workers}_workers"] = frames / seconds
        for size in (84, 256):
            timed(
                [
                    str(BIN / "igen-render"),
                    f"--dataset.root={tmp / 'off'}",
                    f"--cameras=[{','.join(CAMERAS)}]",
                    f"--size={size}",
                    "--num_workers=2",
                    f"--output.root={tmp / f'r{size}_2'}",
                ]
            )
        for size in (84, 128, 256):
            result[f"mb_per_1000_episodes_two_cameras_{size}px"] = folder_bytes(tmp / f"r{size}_2") * per_1000

        # per core: render throughput and what the states cost
        os.sched_setaffinity(0, {0})
        spec = dataset_spec(tmp / "off")
        episodes = load_episodes(tmp / "off", spec)
        states = [s for e in episodes[:5] for s in e.sim_state]
        env = env_cfg.make_task_env()
        env.reset(0)
        for size in (84, 128, 256):
            result[f"render_frames_per_s_per_core_{size}px"] = render_rate(env, states, size)
        env.close()
        result.update(state_cost(env_cfg, 4))
        result.update(write_cost(spec, episodes * 5))
        shutil.rmtree(tmp / "off", ignore_errors=True)
    print(json.dumps(result, indent=2))
    if args.out:
        Path(args.out).write_text(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
