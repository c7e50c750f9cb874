"""Where a Nut-and-Peg policy's trials, or IntervenGen attempts run with it, end.

``--mode=policy``: the policy alone, as ``igen-eval`` runs a trial (seeded per trial), and the first
step at which the nut was held by both pads, lifted off the table, on the peg, and the fingers closed
on air (a missed grasp); the steps at which the place stalled (the task's place mistake signal), and
the stillest second of the held nut in the air off the peg (its least net displacement over the
stall window, and how far from the peg's axis): what the stall's thresholds were chosen on, a place
that succeeds against one that freezes. ``--mode=igen``: generation attempts as ``igen-generate
--mode=igen`` makes them (``--source`` holds the interventions), and after each replayed recovery its
subtask, whether the nut is held and for how many of its steps each arm joint was at the end of its range.
Each line ends with where the nut is at the end: its distance from the peg's axis in the table plane
and its height, in mm, and whether it is still held.

A base policy that cannot finish the place subtask after a recovery makes no IntervenGen episode
(every attempt ends ``failed``), which this tells apart from recoveries that do not regrasp.

    .venv/bin/python benchmarks/nut_and_peg_ends.py --policy PRETRAINED_MODEL --geometry 1 --trials 10
    .venv/bin/python benchmarks/nut_and_peg_ends.py --policy PRETRAINED_MODEL --geometry 2 --trials 12 \
        --mode igen --source outputs/tables/nut_and_peg/data/source_int [--place_budget]
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
    """One trial as igen-eval runs it, with the first step of each milestone and the place's stalls."""
    from igen_lerobot.core.agents import seed_policy
    from lerobot_env_igen.nut_and_peg.env import STALL_STEPS

    obs = env.reset(seed)
    policy.reset()
    seed_policy(policy, seed)
    first: dict[str, int] = {}
    stalls: list[int] = []
    held_in_air: list[np.ndarray | None] = []  # the nut's position while held and lifted off the peg
    success, step = False, max_steps
    for step in range(1, max_steps + 1):
        subtask = env.subtask_index()
        info = env.step(policy.act(obs))
        if info.mistake and subtask == 1:
            stalls.append(step)
        in_air = env.nut_held() and env.nut_lifted() and not env.nut_on_peg()
        held_in_air.append(env.true_object_poses()["nut"][:3, 3] if in_air else None)
        for name, now in (
            ("held", env.nut_held()),
            ("lifted", env.nut_lifted()),
            ("on_peg", env.nut_on_peg()),
            ("closed_on_air", info.mistake and subtask == 0),
        ):
            if now and name not in first:
                first[name] = step
        if info.success:
            success = True
            break
        obs = env.observe()
    stillest = stillest_second(held_in_air, STALL_STEPS, env.true_object_poses()["peg"][:2, 3])
    return {"success": success, "steps": step, "first": first, "stalls": stalls, "stillest": stillest, **nut_end(env)}


def stillest_second(track: list[np.ndarray | None], window: int, peg_xy: np.ndarray) -> dict | None:
    """The least net displacement [mm] of the held nut over ``window`` steps in the air, and where it was."""
    best = None
    for end in range(window, len(track)):
        span = track[end - window : end + 1]
        if any(p is None for p in span):
            continue
        moved = float(np.linalg.norm(span[-1] - span[0]))
        if best is None or moved < best[0]:
            best = (moved, end, span[-1])
    if best is None:
        return None
    moved, end, where = best
    off_axis = float(np.linalg.norm(where[:2] - peg_xy))
    return {"moved_mm": round(1000 * moved, 1), "step": end + 1, "off_axis_mm": round(1000 * off_axis)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--policy", type=Path, required=True, help="a pretrained_model/ folder")
    parser.add_argument("--geometry", choices=("1", "2", "mixture"), default="mixture")
    parser.add_argument("--trials", type=int, default=10)
    parser.add_argument("--seed", type=int, default=777, help="trial seeds: episode_seed(seed, i)")
    parser.add_argument("--mode", choices=("policy", "igen"), default="policy")
    parser.add_argument("--source", type=Path, help="--mode=igen: the source interventions (a LeRobot dataset)")
    parser.add_argument(
        "--place_budget",
        action="store_true",
        help="--mode=igen, a design probe: IntervenGen's mistake budget forces a place recovery too (after "
        "that many policy steps without placing, a source place is replayed), where the task leaves the place "
        "to its stall signal",
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
        from lerobot_env_igen.nut_and_peg.env import NutAndPegEnv

        if args.place_budget:
            NutAndPegEnv.budget_forces_recovery = lambda self, subtask: True
        runner = AttemptRunner(job)
        after_recovery: list[dict] = []
        replay = intervengen.replay_segment

        at_limit: Counter = Counter()  # per arm joint (1-7): steps of the replay within 1 deg of its range's end
        step_to = NutAndPegEnv.step_to

        def traced_step(env, *step_args, **kwargs):
            info = step_to(env, *step_args, **kwargs)
            joints = [int(np.flatnonzero(env.model.jnt_qposadr == adr)[0]) for adr in env.arm.arm_qpos]
            q, limits = env.data.qpos[env.arm.arm_qpos], env.model.jnt_range[joints]
            margin = np.minimum(q - limits[:, 0], limits[:, 1] - q)
            at_limit.update(int(j) + 1 for j in np.flatnonzero(margin < np.radians(1.0)))
            return info

        def traced_replay(env, recorder, obs, segment, *replay_args, flagged: bool, **kwargs):
            at_limit.clear()
            NutAndPegEnv.step_to = traced_step
            try:
                outcome = replay(env, recorder, obs, segment, *replay_args, flagged=flagged, **kwargs)
            finally:
                NutAndPegEnv.step_to = step_to
            if flagged:
                row = {"subtask": segment.subtask, "held": env.nut_held(), "steps": outcome.steps}
                after_recovery.append({**row, "joint_at_limit_steps": dict(sorted(at_limit.items()))})
            return outcome

        intervengen.replay_segment = traced_replay
        for i in range(args.trials):
            after_recovery.clear()
            attempt = runner(i)
            ends[attempt.reason or "kept"] += 1
            row = {"attempt": i, "end": attempt.reason or "kept", "steps": attempt.steps}
            print(json.dumps({**row, "recoveries": list(after_recovery), **nut_end(runner.env)}), flush=True)
    summary = {"policy": str(args.policy), "geometry": args.geometry, "mode": args.mode}
    print(json.dumps({**summary, "place_budget": args.place_budget, **ends}))


if __name__ == "__main__":
    main()
