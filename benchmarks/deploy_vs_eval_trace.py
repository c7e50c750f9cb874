"""Where does a rehearsal trial part ways with igen-eval's rollout of the same trial?

Runs trial ``i`` of a checkpoint twice on the training simulator: igen-eval's rollout (the env's own
observation) and igen-deploy's loop on the MuJoCo arm with the simulator's true cube pose
(``--robot.type=sim --perception.type=truth``). Both start from the same scene, pose error and
policy seed, so until something in the deployment path differs they see the same observations
and take the same actions. Prints, per observation entry, the first step where the two differ by
more than ``--tol`` and by how much, then both paths' outcome.

    MUJOCO_GL=egl python benchmarks/deploy_vs_eval_trace.py CHECKPOINT/pretrained_model --trial 2
"""

from __future__ import annotations

import argparse
import logging

import numpy as np

from igen_lerobot.core.env_config import task_config_class
from igen_lerobot.core.portable_math import rerun_on_portable_paths
from igen_lerobot.core.seeding import episode_seed
from igen_lerobot.evaluation.trials import rollout
from igen_lerobot.training.policy_source import make_base_policy


class RecordingPolicy:
    """Passes every call through to ``policy`` and keeps each observation and action."""

    def __init__(self, policy) -> None:
        self.policy, self.observations, self.actions = policy, [], []

    def act(self, obs: dict) -> np.ndarray:
        action = self.policy.act(obs)
        self.observations.append({k: np.array(v, dtype=float) for k, v in obs.items()})
        self.actions.append(np.array(action, dtype=float).reshape(-1))
        return action

    def __getattr__(self, name: str):
        return getattr(self.policy, name)


def eval_trace(cfg, trial: int):
    env_cfg = task_config_class(cfg.task)()
    policy = RecordingPolicy(make_base_policy(cfg.policy, env_cfg))
    env = env_cfg.make_task_env()
    try:
        success, steps = rollout(env, policy, episode_seed(cfg.seed, trial), cfg.max_steps)
    finally:
        env.close()
    return success, steps, policy.observations, policy.actions


def deploy_last_trial(cfg, trial: int) -> tuple[dict, list]:
    """igen-deploy's trials 0..``trial`` (trial i is igen-eval's trial i); the last one's outcome and step records."""
    from lerobot_robot_igen.deploy.trials import deploy

    records = []
    cfg.trials = trial + 1
    report = deploy(cfg, on_step=records.append)
    # the last trial's records: each trial's steps count up from the same first step again
    first_step = min(r.step for r in records)
    return report["per_trial"][-1], records[max(i for i, r in enumerate(records) if r.step == first_step) :]


def deploy_trace(cfg, trial: int):
    outcome, ours = deploy_last_trial(cfg, trial)
    return outcome["success"], outcome["steps"], [r.observation for r in ours], [r.action for r in ours], ours


def main() -> None:
    import draccus

    from lerobot_robot_igen.deploy.config_deploy import DeployConfig

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("checkpoint")
    parser.add_argument("--trial", type=int, default=0)
    parser.add_argument("--tol", type=float, default=1e-4)
    args = parser.parse_args()
    rerun_on_portable_paths()
    logging.basicConfig(level=logging.WARNING)
    flags = [f"--policy.path={args.checkpoint}", "--robot.type=sim", "--perception.type=truth"]
    cfg = draccus.parse(DeployConfig, args=[*flags, f"--trials={args.trial + 1}"])
    ok_eval, n_eval, obs_eval, act_eval = eval_trace(cfg, args.trial)
    ok_dep, n_dep, obs_dep, act_dep, records = deploy_trace(cfg, args.trial)
    print(
        f"trial {args.trial}: igen-eval {'success' if ok_eval else 'failure'} in {n_eval} steps, "
        f"deployment {'success' if ok_dep else 'failure'} in {n_dep} steps"
    )
    n = min(len(obs_eval), len(obs_dep))
    for key in obs_eval[0]:
        if key not in obs_dep[0]:
            print(f"  {key}: not in the deployment's observation")
            continue
        diffs = [np.abs(np.ravel(obs_eval[t][key]) - np.ravel(obs_dep[t][key])) for t in range(n)]
        first = next((t for t, d in enumerate(diffs) if d.max() > args.tol), None)
        if first is None:
            print(f"  {key}: equal within {args.tol} over {n} steps")
        else:
            d = diffs[first]
            print(
                f"  {key}: first differs at step {first}, entries {np.flatnonzero(d > args.tol).tolist()}, "
                f"max {d.max():.2e}; eval {np.round(np.ravel(obs_eval[first][key]), 4).tolist()} "
                f"deploy {np.round(np.ravel(obs_dep[first][key]), 4).tolist()}"
            )
    first_action = next((t for t in range(n) if np.abs(act_eval[t] - act_dep[t]).max() > args.tol), None)
    print(f"  action: first differs at step {first_action}")
    if first_action is not None:
        t = first_action
        print(f"    eval {np.round(act_eval[t], 4).tolist()} deploy {np.round(act_dep[t], 4).tolist()}")
        r = records[t]
        print(f"    deploy at that step: contact={r.contact} revealed={r.revealed} pose_fresh={r.pose_fresh}")


if __name__ == "__main__":
    main()
