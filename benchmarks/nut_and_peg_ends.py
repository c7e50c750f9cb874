"""Where a Nut-and-Peg policy's trials, or IntervenGen attempts run with it, end.

``--mode=policy``: the policy alone, as ``igen-eval`` runs a trial (seeded per trial), and the first
step at which the nut was held by both pads, lifted off the table, on the peg, and the fingers closed
on air (a missed grasp). ``--mode=igen``: generation attempts as ``igen-generate --mode=igen`` makes
them (``--source`` holds the interventions), and after each replayed recovery whether the nut is held.
Each line ends with where the nut is at the end: its distance from the peg's axis in the table plane
and its height, in mm, and whether it is still held.

A base policy that cannot finish the place subtask after a recovery makes no IntervenGen episode
(every attempt ends ``failed``), which this tells apart from recoveries that do not regrasp.

    .venv/bin/python benchmarks/nut_and_peg_ends.py --policy PRETRAINED_MODEL --geometry 1 --trials 10
    .venv/bin/python benchmarks/nut_and_peg_ends.py --policy PRETRAINED_MODEL --geometry 2 --trials 12 \
        --mode igen --source outputs/tables/nut_and_peg/data/source_int [--place_may_err]
"""

from __future__ import annotations

import argparse
import json
from collections import Counter
from pathlib import Path

import numpy as np
from lerobot.utils.import_utils import register_third_party_plugins

from igen_lerobot.core.portable_math import rerun_on_portable_paths


def nut_end(env) -> dict:
    poses = env.true_object_poses()
    offset = np.linalg.norm(poses["nut"][:2, 3] - poses["peg"][:2, 3])
    height = poses["nut"][2, 3]
    return {"nut_off_peg_mm": round(1000 * offset), "nut_z_mm": round(1000 * height), "held": env.nut_held()}


def policy_trial(env, policy, seed: int, max_steps: int) -> dict:
    """One trial as igen-eval runs it, with the first step of each milestone."""
    from igen_lerobot.core.agents import seed_policy

    obs = env.reset(seed)
    policy.reset()
    seed_policy(policy, seed)
    first: dict[str, int] = {}
    success, step = False, max_steps
    for step in range(1, max_steps + 1):
        info = env.step(policy.act(obs))
        for name, now in (
            ("held", env.nut_held()),
            ("lifted", env.nut_lifted()),
            ("on_peg", env.nut_on_peg()),
            ("closed_on_air", info.mistake),
        ):
            if now and name not in first:
                first[name] = step
        if info.success:
            success = True
            break
        obs = env.observe()
    return {"success": success, "steps": step, "first": first, **nut_end(env)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--policy", type=Path, required=True, help="a pretrained_model/ folder")
    parser.add_argument("--geometry", choices=("1", "2", "mixture"), default="mixture")
    parser.add_argument("--trials", type=int, default=10)
    parser.add_argument("--seed", type=int, default=777, help="trial seeds: episode_seed(seed, i)")
    parser.add_argument("--mode", choices=("policy", "igen"), default="policy")
    parser.add_argument("--source", type=Path, help="--mode=igen: the source interventions (a LeRobot dataset)")
    parser.add_argument(
        "--place_may_err",
        action="store_true",
        help="--mode=igen, a design probe: the place subtask may take a recovery too (after IntervenGen's "
        "mistake budget of policy steps without placing, a source place is replayed), where the task says "
        "nothing there can go wrong",
    )
    args = parser.parse_args()
    rerun_on_portable_paths()  # the table's code paths
    register_third_party_plugins()
    from igen_lerobot.core.seeding import episode_seed
    from igen_lerobot.training.policy_source import PolicySourceConfig, make_base_policy
    from lerobot_env_igen.nut_and_peg.config import NutAndPegEnvConfig

    cfg = NutAndPegEnvConfig(geometry=args.geometry)
    ends: Counter = Counter()
    if args.mode == "policy":
        env = cfg.make_task_env()
        policy = make_base_policy(PolicySourceConfig(path=str(args.policy)), cfg)
        for i in range(args.trials):
            row = policy_trial(env, policy, episode_seed(args.seed, i), cfg.episode_length)
            ends["success" if row["success"] else "failure"] += 1
            print(json.dumps({"trial": i, **row}), flush=True)
    else:
        if args.source is None:
            parser.error("--mode=igen needs --source (the interventions igen-generate replays)")
        import igen_lerobot.generation.intervengen as intervengen
        from igen_lerobot.datasets.reader import load_episodes
        from igen_lerobot.generation.intervengen import IntervenGenConfig
        from igen_lerobot.generation.job import AttemptRunner, GenerationJob, GenerationMode
        from igen_lerobot.generation.sources import parse_interventions

        spec, actions = cfg.task_spec, cfg.make_action_space()
        episodes = load_episodes(args.source, spec, repo_id=None, flag="--source")
        library = parse_interventions(episodes, spec, actions.target_pose, actions.gripper_closed)
        job = GenerationJob(
            mode=GenerationMode.IGEN,
            env_config=cfg,
            library=library,
            run_seed=args.seed,
            max_steps=cfg.episode_length + IntervenGenConfig().mistake_budget,
            policy=PolicySourceConfig(path=str(args.policy)),
        )
        if args.place_may_err:
            from lerobot_env_igen.nut_and_peg.env import NutAndPegEnv

            NutAndPegEnv.mistake_possible = lambda self, subtask: True
        runner = AttemptRunner(job)
        after_recovery: list[dict] = []
        replay = intervengen.replay_segment

        def traced_replay(env, *replay_args, flagged: bool, **kwargs):
            outcome = replay(env, *replay_args, flagged=flagged, **kwargs)
            if flagged:
                after_recovery.append({"held": env.nut_held(), "steps": outcome.steps})
            return outcome

        intervengen.replay_segment = traced_replay
        for i in range(args.trials):
            after_recovery.clear()
            attempt = runner(i)
            ends[attempt.reason or "kept"] += 1
            row = {"attempt": i, "end": attempt.reason or "kept", "steps": attempt.steps}
            print(json.dumps({**row, "recoveries": list(after_recovery), **nut_end(runner.env)}), flush=True)
    summary = {"policy": str(args.policy), "geometry": args.geometry, "mode": args.mode}
    print(json.dumps({**summary, "place_may_err": args.place_may_err, **ends}))


if __name__ == "__main__":
    main()
