"""The control loop of ``bench_env.py`` alone (scripted policy, no timing of its own), to profile.

Run:  MUJOCO_GL=egl py-spy record -r 200 -f raw -o loop.txt -- \\
          .venv/bin/python benchmarks/env_loop.py --task two_piece_assembly --steps 4000
"""

import argparse
import os
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402
from lerobot.utils.import_utils import register_third_party_plugins  # noqa: E402

from igen_lerobot.core.env_config import task_config_class  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--task", default="two_piece_assembly")
    parser.add_argument("--steps", type=int, default=4000)
    args = parser.parse_args()
    register_third_party_plugins()
    cfg = task_config_class(args.task)()
    env = cfg.make_task_env()
    env.reset(0)
    env.step(np.zeros(len(env.spec.action_names)))  # compile the numba kernels first
    policy = cfg.make_scripted_policy()
    done, seed = 0, 0
    start = time.process_time()
    while done < args.steps:
        obs = env.reset(seed)
        for _ in range(cfg.episode_length):
            info = env.step(policy.act(obs))
            obs = env.observe()
            done += 1
            if info.success or done >= args.steps:
                break
        seed += 1
    print(f"{args.task}: {args.steps / (time.process_time() - start):.0f} control steps per CPU second")


if __name__ == "__main__":
    main()
