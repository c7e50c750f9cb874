"""How much a BC-RNN checkpoint's gripper mixture leans to opening at the first step of each trial.

At a hidden-state reset the policy has only the current observation to go on. For each trial of
``igen-eval``'s seeds this takes the checkpoint's first action as ``igen-eval`` does and prints the
mixture's weight on the modes whose gripper mean is an open command, beside the trial's pose error.
A weight that follows the sign of one error component points at that input's normalisation
(docs/results/reproducibility.md: 2-Piece Assembly's receptacle height).

Run:  .venv/bin/python benchmarks/open_weight_at_reset.py --task=two_piece_assembly CHECKPOINT [...]
      [--seed 1000003] [--trials 50] [--per-trial]
"""

from __future__ import annotations

import argparse

import numpy as np
import torch
from lerobot.envs.configs import EnvConfig
from lerobot.utils.import_utils import register_third_party_plugins

from igen_lerobot.core.agents import seed_policy
from igen_lerobot.core.seeding import episode_seed
from igen_lerobot.training.bc_rnn import modeling_bc_rnn
from igen_lerobot.training.policy_source import PolicySourceConfig, make_base_policy


def open_weight(head: modeling_bc_rnn.GMMHead, features: torch.Tensor) -> float:
    """The mixture weight of the modes whose gripper (last action) mean is an open command (< 0)."""
    logits, means, _ = head.parameters_of(features, low_noise=True)
    weights = torch.softmax(logits.reshape(-1, head.num_modes), -1)
    opening = means.reshape(-1, head.num_modes, head.action_dim)[..., -1] < 0
    return float((weights * opening).sum())


def first_step_open_weights(task: str, checkpoint: str, seed: int, trials: int) -> list[tuple[float, np.ndarray]]:
    """(open weight, pose error) at the first step of each trial."""
    config = EnvConfig.get_choice_class(task)()
    env = config.make_task_env()
    policy = make_base_policy(PolicySourceConfig(path=checkpoint), config)
    seen: list[float] = []
    sample = modeling_bc_rnn.GMMHead.sample

    def recording_sample(self, features, low_noise=False, generator=None):
        seen.append(open_weight(self, features))
        return sample(self, features, low_noise, generator)

    modeling_bc_rnn.GMMHead.sample = recording_sample
    rows = []
    try:
        for i in range(trials):
            trial_seed = episode_seed(seed, i)
            obs = env.reset(trial_seed)
            policy.reset()
            seed_policy(policy, trial_seed)
            seen.clear()
            policy.act(obs)
            rows.append((seen[0], np.asarray(env.corruption, dtype=float)))
    finally:
        modeling_bc_rnn.GMMHead.sample = sample
        env.close()
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("checkpoints", nargs="+")
    parser.add_argument("--task", required=True, help="the env type the checkpoints were trained on")
    parser.add_argument("--seed", type=int, default=1000003, help="igen-table's validation seed")
    parser.add_argument("--trials", type=int, default=50)
    parser.add_argument("--per-trial", action="store_true", help="print each trial's weight and pose error")
    args = parser.parse_args()
    register_third_party_plugins()
    for checkpoint in args.checkpoints:
        rows = first_step_open_weights(args.task, checkpoint, args.seed, args.trials)
        if args.per_trial:
            for i, (weight, error) in enumerate(rows):
                print(f"trial {i:2d}  open weight {weight:.3f}  pose error [m] {np.round(error, 4).tolist()}")
        weights = np.array([w for w, _ in rows])
        print(
            f"{checkpoint}: open weight at step 0, mean {weights.mean():.3f}; "
            f"above 0.5 in {(weights > 0.5).sum()}/{len(weights)} trials"
        )


if __name__ == "__main__":
    main()
