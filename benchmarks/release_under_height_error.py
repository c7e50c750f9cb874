"""When a learnt in-hand policy lets go, as a function of the target's observed height error only.

For each scene (the I-Gen attempts' seeds of a table, whose errors lift the target), the sampled
error is kept in x and y and its z component replaced by each value of ``--z_mm`` (``same``: the
sampled one); the policy runs seeded as generation runs it, and the step at which it first
commands the fingers open is printed, with whether the revealing contact came first. A policy
that reacts to the sign of a sub-millimetre error is reading an input normalised by a ~0 std.

Run:  .venv/bin/python benchmarks/release_under_height_error.py --policy=<pretrained_model> \\
          [--task=nut_insertion] [--run_seed=4] [--attempts 1 5 7 8 10] [--z_mm same 0.5 -0.5 flip]
"""

from __future__ import annotations

import argparse

from lerobot.utils.import_utils import register_third_party_plugins

from igen_lerobot.core.agents import seed_policy
from igen_lerobot.core.env_config import task_config_class
from igen_lerobot.core.seeding import episode_seed
from igen_lerobot.training.policy_source import PolicySourceConfig, make_base_policy


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--policy", required=True, help="a pretrained_model folder")
    parser.add_argument("--task", default="nut_insertion")
    parser.add_argument("--run_seed", type=int, default=4, help="the generation run seed (a table's igen step: 4)")
    parser.add_argument("--attempts", type=int, nargs="+", default=[1, 5, 7, 8, 10, 12, 14, 15, 16, 18, 23])
    parser.add_argument("--z_mm", nargs="+", default=["same", "0.5", "-0.5", "flip"])
    parser.add_argument("--steps", type=int, default=120)
    args = parser.parse_args()
    register_third_party_plugins()
    config = task_config_class(args.task)()
    env = config.make_task_env()
    policy = make_base_policy(PolicySourceConfig(path=args.policy), config)
    print("| attempt | z error [mm] | fingers open at step | revealing contact before |")
    print("|---|---|---|---|")
    for attempt in args.attempts:
        seed = episode_seed(args.run_seed, attempt)
        env.reset(seed)
        sampled = env.corruption.copy()
        for z in args.z_mm:
            error = sampled.copy()
            named = {"same": sampled[2], "flip": -sampled[2]}
            error[2] = named[z] if z in named else float(z) / 1000
            obs = env.reset(seed, corruption=error)
            policy.reset()
            seed_policy(policy, seed)
            opened = "never"
            for step in range(args.steps):
                action = policy.act(obs)
                if not env.gripper_command(action):
                    opened = str(step)
                    break
                env.step(action)
                obs = env.observe()
            print(f"| {attempt} | {1000 * error[2]:+.1f} | {opened} | {'yes' if env.contact else 'no'} |")
    env.close()


if __name__ == "__main__":
    main()
