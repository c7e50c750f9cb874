"""BC-RNN as a LeRobot policy plugin: registered, trained by lerobot-train, reloaded, acting."""

import json
import logging
from pathlib import Path

import numpy as np
import pytest
import torch

from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.datasets.reader import load_episodes


def test_bc_rnn_is_found_by_lerobot_plugin_discovery():
    from lerobot.configs.policies import PreTrainedConfig
    from lerobot.utils.import_utils import register_third_party_plugins

    register_third_party_plugins()
    assert "bc_rnn" in PreTrainedConfig.get_known_choices()


def test_gmm_loss_is_the_negative_log_likelihood_and_ignores_padding():
    from lerobot.configs import FeatureType, PolicyFeature

    from igen_lerobot.training.bc_rnn.configuration_bc_rnn import BCRNNConfig
    from igen_lerobot.training.bc_rnn.modeling_bc_rnn import BCRNNPolicy

    torch.manual_seed(0)
    config = BCRNNConfig(
        rnn_hidden_dim=16,
        horizon=4,
        input_features={"observation.state": PolicyFeature(FeatureType.STATE, (3,))},
        output_features={"action": PolicyFeature(FeatureType.ACTION, (2,))},
    )
    policy = BCRNNPolicy(config)
    batch = {
        "observation.state": torch.randn(5, 4, 3),
        "action": torch.rand(5, 4, 2) * 2 - 1,
        "action_is_pad": torch.zeros(5, 4, dtype=torch.bool),
    }
    loss, info = policy.forward(batch)
    dist, _ = policy._distribution(batch["observation.state"])
    assert torch.isclose(loss, -dist.log_prob(batch["action"]).mean())
    padded = dict(batch, action_is_pad=torch.tensor([[False, False, True, True]] * 5))
    changed = dict(padded, action=batch["action"].clone())
    changed["action"][:, 2:] = 0.9  # padded steps must not matter
    assert torch.isclose(policy.forward(padded)[0], policy.forward(changed)[0])
    # a few optimisation steps raise the likelihood of the data
    optim = torch.optim.Adam(policy.parameters(), lr=1e-2)
    start = loss.item()
    for _ in range(30):
        optim.zero_grad()
        policy.forward(batch)[0].backward()
        optim.step()
    assert policy.forward(batch)[0].item() < start - 1.0


def test_rnn_state_is_reset_every_horizon_steps():
    from lerobot.configs import FeatureType, PolicyFeature

    from igen_lerobot.training.bc_rnn.configuration_bc_rnn import BCRNNConfig
    from igen_lerobot.training.bc_rnn.modeling_bc_rnn import BCRNNPolicy

    config = BCRNNConfig(
        rnn_hidden_dim=8,
        horizon=3,
        input_features={"observation.state": PolicyFeature(FeatureType.STATE, (2,))},
        output_features={"action": PolicyFeature(FeatureType.ACTION, (1,))},
    )
    policy = BCRNNPolicy(config)
    obs = {"observation.state": torch.ones(1, 2)}
    hidden_after = []
    for _ in range(4):
        policy.select_action(obs)
        hidden_after.append(policy._hidden[0].clone())
    # step 4 starts from a fresh state, like step 1: same input, same state
    assert torch.allclose(hidden_after[3], hidden_after[0])
    assert not torch.allclose(hidden_after[1], hidden_after[0])


@pytest.mark.parametrize("rnn_type", ["LSTM", "GRU"])
def test_a_batch_of_trials_steps_each_row_as_alone_where_the_rnn_allows(rnn_type):
    """Grouped evaluation relies on torch's CPU LSTM computing each row the same for any batch size
    (tolerance 0); its GRU does not, so a GRU policy declines grouping instead of changing numbers."""
    from lerobot.configs import FeatureType, PolicyFeature

    from igen_lerobot.training.bc_rnn.configuration_bc_rnn import BCRNNConfig
    from igen_lerobot.training.bc_rnn.modeling_bc_rnn import BCRNNPolicy

    torch.manual_seed(0)
    config = BCRNNConfig(
        rnn_type=rnn_type,
        rnn_hidden_dim=33,
        horizon=4,
        input_features={"observation.state": PolicyFeature(FeatureType.STATE, (5,))},
        output_features={"action": PolicyFeature(FeatureType.ACTION, (3,))},
    )
    policy = BCRNNPolicy(config)
    inputs = torch.randn(9, 6, 5)  # 9 trials, 6 steps: past the horizon's reset
    alone = []
    for k in range(9):
        policy.reset()
        torch.manual_seed(100 + k)
        alone.append(
            torch.stack([policy.select_action({"observation.state": inputs[k : k + 1, t]})[0] for t in range(6)])
        )
    policy.reset()
    generators = [torch.Generator().manual_seed(100 + k) for k in range(9)]
    together = torch.stack(
        [policy.select_action_per_trial({"observation.state": inputs[:, t]}, generators) for t in range(6)], dim=1
    )
    exact = all(torch.equal(together[k], alone[k]) for k in range(9))
    assert policy.trials_batch_exactly == (rnn_type == "LSTM")
    assert exact == (rnn_type == "LSTM")


def _small_policy(hidden: int = 24):
    from lerobot.configs import FeatureType, PolicyFeature

    from igen_lerobot.training.bc_rnn.configuration_bc_rnn import BCRNNConfig
    from igen_lerobot.training.bc_rnn.modeling_bc_rnn import BCRNNPolicy

    torch.manual_seed(0)
    config = BCRNNConfig(
        rnn_hidden_dim=hidden,
        horizon=4,
        input_features={"observation.state": PolicyFeature(FeatureType.STATE, (5,))},
        output_features={"action": PolicyFeature(FeatureType.ACTION, (3,))},
    )
    return BCRNNPolicy(config)


def test_amp_runs_the_lstm_in_bfloat16_and_the_mixture_in_float32():
    """``--policy.use_amp`` (LeRobot's accelerate autocast, bfloat16 on CPU) speeds up the LSTM; the
    mixture's likelihood with scales down to 1e-4 stays float32. Tolerance: the bfloat16 loss is
    within 5% of the float32 loss on the same weights."""
    policy = _small_policy()
    batch = {"observation.state": torch.randn(8, 4, 5), "action": torch.rand(8, 4, 3) * 2 - 1}
    seen = {}
    policy.rnn.register_forward_hook(lambda module, args, out: seen.__setitem__("rnn", out[0].dtype))
    policy.head.register_forward_hook(lambda module, args, out: seen.__setitem__("head", out.mean.dtype))
    full, _ = policy.forward(batch)
    assert seen == {"rnn": torch.float32, "head": torch.float32}
    with torch.autocast("cpu", dtype=torch.bfloat16):
        mixed, _ = policy.forward(batch)
    # oneDNN has a bfloat16 LSTM on avx512 CPUs only; elsewhere the LSTM falls back to float32
    try:
        with torch.autocast("cpu", dtype=torch.bfloat16):
            torch.nn.LSTM(5, 4, batch_first=True)(torch.randn(2, 3, 5))
        lstm_dtype = torch.bfloat16
    except RuntimeError:
        lstm_dtype = torch.float32
    assert seen == {"rnn": lstm_dtype, "head": torch.float32}
    assert mixed.dtype == torch.float32
    assert abs(mixed.item() - full.item()) <= 0.05 * abs(full.item())
    mixed.backward()
    assert all(p.grad is not None and p.grad.dtype == torch.float32 for p in policy.parameters())


def test_acting_is_float32_even_under_autocast():
    """lerobot-eval autocasts ``select_action`` when the policy was trained with use_amp; the actions
    must still be the float32 ones that igen-eval and a grouped evaluation take (tolerance 0)."""
    policy = _small_policy()
    inputs = torch.randn(6, 2, 5)
    actions = {}
    for autocast in (False, True):
        policy.reset()
        torch.manual_seed(7)
        with torch.autocast("cpu", dtype=torch.bfloat16, enabled=autocast):
            actions[autocast] = torch.stack([policy.select_action({"observation.state": inputs[t]}) for t in range(6)])
            grouped = policy.select_action_per_trial({"observation.state": inputs[0]}, [torch.Generator()] * 2)
        assert grouped.dtype == torch.float32
    assert actions[True].dtype == torch.float32
    assert torch.equal(actions[True], actions[False])


def test_lerobot_train_checkpoint_loads_and_acts_in_our_env(bc_rnn_checkpoint, block_grasp_env, source_demos):
    from igen_lerobot.training.checkpoint_policy import LeRobotCheckpointPolicy

    policy = LeRobotCheckpointPolicy(bc_rnn_checkpoint, block_grasp_env.spec)
    assert policy.type == "bc_rnn"
    obs = block_grasp_env.reset(0)
    policy.reset()
    for _ in range(5):
        action = policy.act(obs)
        assert action.shape == (4,) and np.all(np.isfinite(action))
        block_grasp_env.step(action)
        obs = block_grasp_env.observe()
    # unnormalised into the dataset's action range (min/max normalisation, tanh-bounded means)
    actions = np.concatenate([e.action for e in load_episodes(source_demos, block_grasp_env.spec)])
    assert np.all(action >= actions.min(axis=0) - 1e-3) and np.all(action <= actions.max(axis=0) + 1e-3)


def test_checkpoint_of_another_feature_set_is_rejected(bc_rnn_checkpoint, block_grasp_env):
    from igen_lerobot.core.belief import Reveal
    from igen_lerobot.core.exceptions import TaskMismatchError
    from igen_lerobot.training.checkpoint_policy import LeRobotCheckpointPolicy

    # the same task under another reveal mode observes three more values (the direction hint)
    other = block_grasp_env.spec.with_reveal(Reveal.DIRECTION)
    assert len(other.env_state_names) == len(block_grasp_env.spec.env_state_names) + 3
    with pytest.raises(TaskMismatchError, match="observation.environment_state of shape"):
        LeRobotCheckpointPolicy(bc_rnn_checkpoint, other)


def test_fast_rollout_sampler_draws_from_the_same_mixture():
    """select_action samples without distribution objects; it must match MixtureSameFamily.sample."""
    import torch

    from igen_lerobot.training.bc_rnn.modeling_bc_rnn import GMMHead

    torch.manual_seed(0)
    head = GMMHead(in_dim=8, action_dim=3, num_modes=5, min_std=0.01)
    features = torch.randn(2, 8)
    n = 200_000
    with torch.no_grad():
        fast = head.sample(features.expand(n, 2, 8).reshape(n * 2, 8)).reshape(n, 2, 3)
        reference = head(features).sample((n,))  # (n, 2, 3)
    # moments agree within sampling error: sample std <= 1.5, so the difference of two means has
    # std <= 1.5 * sqrt(2 / 200000) = 0.0047; 0.025 is > 5 of those
    assert torch.allclose(fast.mean(0), reference.mean(0), atol=0.025)
    assert torch.allclose(fast.std(0), reference.std(0), atol=0.025)
    # and a low-noise draw is (almost) one of the component means
    with torch.no_grad():
        _, means, _ = head.parameters_of(features)
        low = head.sample(features, low_noise=True)
    distance = (means - low[:, None, :]).norm(dim=-1).min(dim=-1).values
    assert (distance < 1e-3).all()


def test_cosine_schedule_anneals_the_rate_to_zero_over_the_training_steps():
    from igen_lerobot.core.exceptions import ConfigError
    from igen_lerobot.training.bc_rnn.configuration_bc_rnn import BCRNNConfig

    assert BCRNNConfig(lr_schedule="constant").get_scheduler_preset() is None  # robomimic's constant rate
    assert BCRNNConfig().lr_schedule == "cosine"  # the default since the schedule study (docs/results.md)
    preset = BCRNNConfig().get_scheduler_preset()
    weight = torch.nn.Parameter(torch.zeros(1))
    optimizer = torch.optim.Adam([weight], lr=1e-3)
    scheduler = preset.build(optimizer, num_training_steps=100)
    rates = []
    for _ in range(100):
        rates.append(optimizer.param_groups[0]["lr"])
        optimizer.step()
        scheduler.step()
    assert rates[0] == pytest.approx(1e-3) and rates[50] == pytest.approx(5e-4, rel=0.05)
    assert optimizer.param_groups[0]["lr"] == pytest.approx(0.0, abs=1e-12)
    assert all(a >= b for a, b in zip(rates, rates[1:], strict=False))
    with pytest.raises(ConfigError, match="policy.lr_schedule must be one of"):
        BCRNNConfig(lr_schedule="linear")


def test_std_tolerance_bounds_how_far_a_constant_input_is_amplified(caplog):
    from lerobot.configs import FeatureType, PolicyFeature

    from igen_lerobot.training.bc_rnn.configuration_bc_rnn import BCRNNConfig
    from igen_lerobot.training.bc_rnn.processor_bc_rnn import make_bc_rnn_pre_post_processors

    features = {
        "observation.state": PolicyFeature(FeatureType.STATE, (2,)),
        "observation.environment_state": PolicyFeature(FeatureType.ENV, (2,)),
    }
    stats = {  # the second env input never varied in the data (a fixed peg's height)
        "observation.state": {"mean": np.array([0.5, 0.0]), "std": np.array([0.1, 0.2])},
        "observation.environment_state": {"mean": np.array([0.0, 0.865]), "std": np.array([0.03, 0.0])},
        "action": {"min": np.array([-1.0, -1.0]), "max": np.array([1.0, 1.0])},
    }
    error = 0.001  # a 1 mm observation error on the constant input

    def normalised_error(tolerance: float, constant_std: float = 0.0, index: int = 1) -> float:
        config = BCRNNConfig(
            obs_std_tolerance=tolerance,
            constant_input_std=constant_std,
            input_features=features,
            output_features={"action": PolicyFeature(FeatureType.ACTION, (2,))},
        )
        pre, _ = make_bc_rnn_pre_post_processors(config, stats)
        obs = {
            "observation.state": torch.tensor([[0.5, 0.0]]),
            "observation.environment_state": torch.tensor([[0.03, 0.865 + error]]),
        }
        out = pre(obs)
        return float(out["observation.environment_state"][0, index])

    with caplog.at_level(logging.WARNING):
        assert normalised_error(0.0) > 1e4  # LeRobot's eps alone: the 1 mm error becomes ~1e5 std
    assert "observation.environment_state[1]" in caplog.text and "obs_std_tolerance" in caplog.text
    caplog.clear()
    assert normalised_error(1e-3) == pytest.approx(1.0, rel=1e-3)  # robomimic's tolerance: one unit
    assert "never vary" not in caplog.text  # nothing to warn about once the tolerance bounds it
    # a constant input given std 1 keeps its deviation in its own units (1 mm -> 0.001); a varying one is untouched
    assert normalised_error(0.0, constant_std=1.0) == pytest.approx(error, rel=1e-3)
    assert normalised_error(0.0, constant_std=1.0, index=0) == pytest.approx(1.0, rel=1e-4)  # 0.03 at std 0.03
    assert BCRNNConfig().constant_input_std == 1.0  # the default since the Nut Insertion finding
    with pytest.raises(Exception, match="constant_input_std"):
        BCRNNConfig(constant_input_std=-1.0)
    with pytest.raises(Exception, match="obs_std_tolerance"):
        BCRNNConfig(obs_std_tolerance=-1.0)


def test_another_datasets_statistics_normalise_the_inputs_and_the_actions_keep_their_own(tmp_path):
    """``--policy.observation_stats=<D>``: a row normalises its inputs with D's statistics (where its own
    were made tiny by a few added episodes) and its actions with its own; a bad root names the flag."""
    from lerobot.configs import FeatureType, PolicyFeature

    from igen_lerobot.training.bc_rnn.configuration_bc_rnn import BCRNNConfig
    from igen_lerobot.training.bc_rnn.processor_bc_rnn import make_bc_rnn_pre_post_processors

    features = {"observation.environment_state": PolicyFeature(FeatureType.ENV, (2,))}
    own = {  # the peg height varies only in 10 added episodes: std 1.3 mm
        "observation.environment_state": {"mean": np.array([0.0, 0.864]), "std": np.array([0.03, 0.0013])},
        "action": {"min": np.array([-0.5]), "max": np.array([0.5])},
    }
    base = tmp_path / "base"
    (base / "meta").mkdir(parents=True)
    d_stats = {"observation.environment_state": {"mean": [0.01, 0.865], "std": [0.02, 0.0]}}
    (base / "meta" / "stats.json").write_text(json.dumps(d_stats))

    def processors(root: Path | None):
        config = BCRNNConfig(
            observation_stats=None if root is None else str(root),
            input_features=features,
            output_features={"action": PolicyFeature(FeatureType.ACTION, (1,))},
        )
        return make_bc_rnn_pre_post_processors(config, own)

    obs = {"observation.environment_state": torch.tensor([[0.03, 0.835]])}  # a 3 cm height error
    own_input = processors(None)[0](obs)["observation.environment_state"][0]
    assert float(own_input[1]) < -20  # amplified by its own tiny std
    pre, post = processors(base)
    d_input = pre(obs)["observation.environment_state"][0]
    assert float(d_input[0]) == pytest.approx((0.03 - 0.01) / 0.02, rel=1e-4)
    assert float(d_input[1]) == pytest.approx(-0.03, rel=1e-3)  # D never varied it: kept in metres
    assert float(post(torch.tensor([[1.0]]))[0, 0]) == pytest.approx(0.5, rel=1e-5)  # own action range
    with pytest.raises(ConfigError, match=r"policy.observation_stats=.*holds no meta/stats.json"):
        processors(tmp_path / "nowhere")
    elsewhere = {"observation.state": d_stats["observation.environment_state"]}
    (base / "meta" / "stats.json").write_text(json.dumps(elsewhere))
    with pytest.raises(ConfigError, match=r"has no mean/std for \['observation.environment_state'\]"):
        processors(base)


def test_an_input_constant_in_the_data_is_found_by_its_range_when_lerobots_std_is_not_zero():
    """2-Piece Assembly's receptacle height: 0.82 in every frame, yet LeRobot's episode stats give it a std."""
    from lerobot.configs import FeatureType, PolicyFeature
    from lerobot.datasets.compute_stats import aggregate_stats, compute_episode_stats

    from igen_lerobot.training.bc_rnn.configuration_bc_rnn import BCRNNConfig
    from igen_lerobot.training.bc_rnn.processor_bc_rnn import make_bc_rnn_pre_post_processors

    rng = np.random.default_rng(0)
    episodes = []
    for _ in range(3):  # a varying input beside the receptacle's fixed height, as a generated dataset writes them
        column = np.stack([rng.normal(0.0, 0.03, 50), np.full(50, 0.82)], axis=1).astype(np.float32)
        features = {"observation.environment_state": {"dtype": "float32", "shape": (2,)}}
        episodes.append(compute_episode_stats({"observation.environment_state": column}, features))
    env_stats = aggregate_stats(episodes)["observation.environment_state"]
    assert env_stats["max"][1] == env_stats["min"][1]
    assert env_stats["std"][1] > 1e-6, "LeRobot's float32 E[x^2] - E[x]^2 no longer leaves a std here: revisit"

    config = BCRNNConfig(
        input_features={"observation.environment_state": PolicyFeature(FeatureType.ENV, (2,))},
        output_features={"action": PolicyFeature(FeatureType.ACTION, (1,))},
    )
    stats = {
        "observation.environment_state": env_stats,
        "action": {"min": np.array([-1.0]), "max": np.array([1.0])},
    }
    pre, _ = make_bc_rnn_pre_post_processors(config, stats)
    error = 0.01  # a 1 cm error on the observed height, as the paper's error model draws
    out = pre({"observation.environment_state": torch.tensor([[0.0, 0.82 + error]])})
    # in its own units, as robomimic's unnormalised inputs (the std 3e-4 would make it ~30 std)
    assert float(out["observation.environment_state"][0, 1]) == pytest.approx(error, rel=1e-3)
    # the varying input keeps its own std: 0.03 reads as about one std
    varying = pre({"observation.environment_state": torch.tensor([[0.03, 0.82]])})
    assert float(varying["observation.environment_state"][0, 0]) == pytest.approx(
        (0.03 - env_stats["mean"][0]) / env_stats["std"][0], rel=1e-3
    )
