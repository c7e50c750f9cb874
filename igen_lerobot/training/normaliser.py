"""Whose statistics normalise a policy's inputs when it trains on D plus something else.

LeRobot normalises with the training data's own statistics. A dataset made of D and a few added
episodes then takes the std of every input that D holds still from those few frames alone (a peg's
observed height under error): that input reaches the network as tens of standard deviations, and
one odd episode among a thousand is enough (docs/results.md, "One normaliser for every row").
"base" gives such a training D's statistics instead (BC-RNN's ``--policy.observation_stats``), so
policies trained on D and on D + more read their inputs alike; "own" keeps LeRobot's behaviour.
"""

from __future__ import annotations

from pathlib import Path

from igen_lerobot.core.exceptions import ConfigError

OBSERVATION_STATS = ("base", "own")
# the policies that take another dataset's statistics (igen_lerobot.training.bc_rnn's config field)
TAKES_OBSERVATION_STATS = ("bc_rnn",)


def check_observation_stats(choice: str, policy_type: str, flag: str = "--observation_stats") -> None:
    """A clear error for an unknown choice, or for "base" with a policy that cannot take it."""
    if choice not in OBSERVATION_STATS:
        raise ConfigError(f"{flag} must be one of {list(OBSERVATION_STATS)}, got {choice!r}")
    if choice == "base" and policy_type not in TAKES_OBSERVATION_STATS:
        raise ConfigError(
            f"{flag}=base sets BC-RNN's --policy.observation_stats, which --train.policy_type={policy_type} "
            f"lacks; pass {flag}=own"
        )


def observation_stats_args(choice: str, base_dataset: Path, dataset: Path) -> list[str]:
    """The ``lerobot-train`` flags that normalise a training on ``dataset`` with D's statistics.

    None when the training is on D itself (its own statistics are D's) or the choice is "own".
    """
    if choice != "base" or Path(dataset) == Path(base_dataset):
        return []
    return [f"--policy.observation_stats={base_dataset}"]
