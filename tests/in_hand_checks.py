"""Checks every in-hand insertion task's env tests make alike (Nut Insertion, 2-Piece Assembly, Coffee).

Each task's own test file says what is particular to it (its part, target, clearance and heights);
these helpers hold what is the same: the target's placement region, the never-told scripted policy,
and the scripted operator's recovery after the first contact.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from igen_lerobot.collection.record import record_intervention
from igen_lerobot.core.belief import Reveal
from igen_lerobot.core.seeding import episode_seed
from igen_lerobot.core.task import FrameSource

REGION_HALF = 0.05  # [m] the paper's 10 x 10 cm placement region, centred on the table's origin


def assert_placed_over_the_region_without_recompiling(env, target: str, centres: np.ndarray) -> None:
    """``centres`` (N, 2) of ``target`` over N seeds fill the region, and a reset moves it in one model."""
    assert np.all(np.abs(centres) <= REGION_HALF + 1e-9)  # the 10 x 10 cm region ...
    assert np.ptp(centres[:, 0]) > 0.07 and np.ptp(centres[:, 1]) > 0.07  # ... and it is used
    model = env.model  # the fixed target is moved at reset without recompiling: one model, the body moves
    env.reset(1)
    first = env.data.xpos[env.bodies[target]].copy()
    env.reset(2)
    assert env.model is model and not np.allclose(first, env.data.xpos[env.bodies[target]])


def blind_insertion(config, error_model, corruption):
    """The scripted policy believing the target ``corruption`` (x, y, z) [m] off, never told better.

    ``error_model`` only has to admit ``corruption``; returns the env (to inspect, then close) and
    whether the episode succeeded.
    """
    cfg = dataclasses.replace(config, corruption=error_model, reveal=Reveal.NONE)
    env, policy = cfg.make_task_env(), cfg.make_scripted_policy()
    obs = env.reset(0, corruption=np.asarray(corruption, dtype=float))
    success = False
    for _ in range(cfg.episode_length):
        success = env.step(policy.act(obs)).success
        obs = env.observe()
        if success:
            break
    return env, success


def assert_the_operator_recovers(cfg, part: str, clear_of_z: float, episodes: int) -> None:
    """Human-gated episodes of the scripted operator: every one succeeds, the takeover is the operator's
    and comes at the revealing contact, and ``part``'s centre rises above ``clear_of_z`` [m] after it
    (lifted clear of the rim before going in again)."""
    env, policy, operator = cfg.make_task_env(), cfg.make_scripted_policy(), cfg.make_scripted_operator()
    spec = cfg.task_spec
    for i in range(episodes):
        ep = record_intervention(env, policy, operator, episode_seed(1, i), cfg.episode_length)
        assert ep.success and ep.is_intervention.any()
        takeover = int(np.flatnonzero(ep.is_intervention)[0])
        assert ep.source[takeover] == FrameSource.OPERATOR and ep.env_state[takeover, spec.env_state_index("revealed")]
        part_z = ep.true_object_pose[takeover:, spec.objects.index(part) * 7 + 2]
        assert part_z.max() > clear_of_z
    env.close()
