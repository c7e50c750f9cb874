"""BC-RNN: an LSTM over low-dim observations with a Gaussian-mixture action head (robomimic).

Training sees sequences of ``horizon`` steps (LeRobot delta timestamps) and maximises the
log-likelihood of the recorded actions under the mixture, ignoring padded steps past an
episode's end. At rollout the policy carries its RNN state from step to step and resets it
every ``horizon`` steps and at every episode start.

LeRobot's ``--policy.use_amp`` trains under autocast (bfloat16 on CPU): BC-RNN then runs only its
LSTM in bfloat16 and keeps its mixture in float32, and it always acts in float32, so ``igen-eval``
and ``lerobot-eval`` (which autocasts when the flag is set) give the same actions. The tables do not
use it: about 1.35x less CPU a step, but a policy that learnt less (docs/benchmarks.md).
"""

from __future__ import annotations

import functools
import logging

import torch
from lerobot.policies.pretrained import PreTrainedPolicy
from torch import Tensor, nn
from torch.distributions import Categorical, Independent, MixtureSameFamily, Normal

from igen_lerobot.training.bc_rnn.configuration_bc_rnn import BCRNNConfig

logger = logging.getLogger(__name__)

ACTION = "action"
LOW_NOISE_STD = 1e-4


def _float32(device_type: str) -> torch.autocast:
    """A block with autocast off: the head's likelihood, and acting."""
    return torch.autocast(device_type, enabled=False)


def _acts_in_float32(method):
    """Run an acting method with autocast off on the policy's device."""

    @functools.wraps(method)
    def acting(self, *args, **kwargs):
        with _float32(torch.device(self.config.device or "cpu").type):
            return method(self, *args, **kwargs)

    return acting


class GMMHead(nn.Module):
    """Per-step mixture of ``num_modes`` diagonal Gaussians over the (normalised) action."""

    def __init__(self, in_dim: int, action_dim: int, num_modes: int, min_std: float) -> None:
        super().__init__()
        self.action_dim, self.num_modes, self.min_std = action_dim, num_modes, min_std
        self.means = nn.Linear(in_dim, num_modes * action_dim)
        self.scales = nn.Linear(in_dim, num_modes * action_dim)
        self.logits = nn.Linear(in_dim, num_modes)

    def parameters_of(self, features: Tensor, low_noise: bool = False) -> tuple[Tensor, Tensor, Tensor]:
        """Mixture logits (..., K), component means and scales (..., K, A)."""
        shape = (*features.shape[:-1], self.num_modes, self.action_dim)
        means = torch.tanh(self.means(features).reshape(shape))
        if low_noise:
            scales = torch.full_like(means, LOW_NOISE_STD)
        else:
            scales = nn.functional.softplus(self.scales(features).reshape(shape)) + self.min_std
        return self.logits(features), means, scales

    def forward(self, features: Tensor, low_noise: bool = False) -> MixtureSameFamily:
        logits, means, scales = self.parameters_of(features, low_noise)
        components = Independent(Normal(means, scales), 1)
        return MixtureSameFamily(Categorical(logits=logits), components)

    def sample(self, features: Tensor, low_noise: bool = False, generator: torch.Generator | None = None) -> Tensor:
        """A draw from the mixture, without building distribution objects (3x faster per control step).

        ``generator``: where the draws come from (default: torch's global generator).
        """
        logits, means, scales = self.parameters_of(features, low_noise)
        flat = logits.reshape(-1, self.num_modes)
        mode = torch.multinomial(torch.softmax(flat, dim=-1), 1, generator=generator)
        index = mode.reshape(*logits.shape[:-1], 1, 1).expand(*logits.shape[:-1], 1, self.action_dim)
        mean = means.gather(-2, index).squeeze(-2)
        scale = scales.gather(-2, index).squeeze(-2)
        if generator is None:
            return mean + scale * torch.randn_like(mean)
        return mean + scale * torch.randn(mean.shape, generator=generator, dtype=mean.dtype, device=mean.device)


class BCRNNPolicy(PreTrainedPolicy):
    """Recurrent behaviour cloning (robomimic BC-RNN-GMM) for low-dim observations."""

    config_class = BCRNNConfig
    name = "bc_rnn"

    def __init__(self, config: BCRNNConfig, **kwargs) -> None:
        super().__init__(config)
        config.validate_features()
        self.config = config
        self.input_keys = sorted(config.input_features)
        in_dim = sum(config.input_features[k].shape[0] for k in self.input_keys)
        rnn_cls = nn.LSTM if config.rnn_type == "LSTM" else nn.GRU
        self.rnn = rnn_cls(in_dim, config.rnn_hidden_dim, config.rnn_num_layers, batch_first=True)
        layers: list[nn.Module] = []
        width = config.rnn_hidden_dim
        for dim in config.mlp_dims:
            layers += [nn.Linear(width, dim), nn.ReLU()]
            width = dim
        self.mlp = nn.Sequential(*layers)
        action_dim = config.action_feature.shape[0]
        self.head = GMMHead(width, action_dim, config.gmm_num_modes, config.gmm_min_std)
        self.reset()

    def get_optim_params(self) -> dict:
        return self.parameters()

    def reset(self) -> None:
        """Forget the RNN state (called at every episode start)."""
        self._hidden = None
        self._steps = 0

    def _inputs(self, batch: dict[str, Tensor]) -> Tensor:
        return torch.cat([batch[k] for k in self.input_keys], dim=-1)

    def _rnn(self, inputs: Tensor, hidden=None):
        """The LSTM, under the active autocast where this CPU can run it so, else in float32.

        oneDNN has no bfloat16 LSTM on CPUs without avx512 (it cannot create the primitive): there
        ``--policy.use_amp`` trains the LSTM in float32, as if the flag were off for it, and logs once.
        """
        autocast = torch.is_autocast_enabled(inputs.device.type)
        if not (autocast and getattr(self, "_rnn_in_float32", False)):
            try:
                return self.rnn(inputs, hidden)
            except RuntimeError as error:
                if not (autocast and "LSTM" in str(error)):
                    raise
                logger.warning("this CPU has no bfloat16 LSTM (%s); the LSTM runs in float32", str(error)[:80])
                self._rnn_in_float32 = True  # found once: every later step goes straight to float32
        with _float32(inputs.device.type):
            return self.rnn(inputs.float(), hidden)

    def _distribution(self, inputs: Tensor, hidden=None, low_noise: bool = False):
        """The action mixture after the RNN; the RNN alone follows an active autocast (``--policy.use_amp``).

        The head and its likelihood stay in float32: a mixture of scales down to ``gmm_min_std``
        (1e-4) cannot be evaluated in bfloat16's 8 bits of mantissa.
        """
        out, hidden = self._rnn(inputs, hidden)
        with _float32(out.device.type):
            return self.head(self.mlp(out.float()), low_noise=low_noise), hidden

    def forward(self, batch: dict[str, Tensor]) -> tuple[Tensor, dict]:
        inputs = self._inputs(batch)  # (B, T, D) from LeRobot's delta timestamps
        if inputs.dim() == 2:
            inputs = inputs.unsqueeze(1)
        actions = batch[ACTION]
        if actions.dim() == 2:
            actions = actions.unsqueeze(1)
        dist, _ = self._distribution(inputs)
        log_prob = dist.log_prob(actions)  # (B, T)
        valid = ~batch["action_is_pad"] if "action_is_pad" in batch else torch.ones_like(log_prob, dtype=torch.bool)
        loss = -(log_prob * valid).sum() / valid.sum().clamp_min(1)
        return loss, {"log_likelihood": -loss.item()}

    @torch.no_grad()
    def predict_action_chunk(self, batch: dict[str, Tensor]) -> Tensor:
        """One action per call (an RNN policy has no chunks): shape (B, 1, action_dim)."""
        return self.select_action(batch).unsqueeze(1)

    @torch.no_grad()
    @_acts_in_float32
    def select_action(self, batch: dict[str, Tensor]) -> Tensor:
        self.eval()
        if self._steps % self.config.horizon == 0:
            self._hidden = None  # robomimic resets the RNN every `horizon` rollout steps
        inputs = self._inputs(batch).unsqueeze(1)  # (B, 1, D)
        out, self._hidden = self.rnn(inputs, self._hidden)
        self._steps += 1
        return self.head.sample(self.mlp(out), low_noise=self.config.low_noise_eval)[:, 0]

    @property
    def trials_batch_exactly(self) -> bool:
        """Whether :meth:`select_action_per_trial` gives each row, bit for bit, what it gets alone.

        On CPU torch's LSTM keeps every row's arithmetic the same for any batch size; its GRU does not
        (measured: tests/test_bc_rnn.py).
        """
        return self.config.rnn_type == "LSTM" and self.config.device in (None, "cpu")

    @torch.no_grad()
    @_acts_in_float32
    def select_action_per_trial(self, batch: dict[str, Tensor], generators: list[torch.Generator]) -> Tensor:
        """:meth:`select_action` for B trials stepped together, row ``k`` drawing from ``generators[k]``.

        Row ``k`` gets, bit for bit, what ``select_action`` gives trial ``k`` alone after
        ``torch.manual_seed`` with its seed: the LSTM, the one costly part, runs on the whole batch
        (on CPU its rows do not depend on each other or on the batch size: tests/test_bc_rnn.py); the
        head runs row by row, because a matrix product over B rows may sum in another order than
        over one, and each row draws from its own generator.
        """
        self.eval()
        if self._steps % self.config.horizon == 0:
            self._hidden = None
        inputs = self._inputs(batch).unsqueeze(1)  # (B, 1, D)
        out, self._hidden = self.rnn(inputs, self._hidden)
        self._steps += 1
        low_noise = self.config.low_noise_eval
        # each row copied to a buffer of its own, aligned as a lone trial's output is: a view at row k's
        # offset takes other vectorised paths through the head's products and gives other last bits
        rows = [
            self.head.sample(self.mlp(out[k : k + 1].clone()), low_noise, g)[:, 0] for k, g in enumerate(generators)
        ]
        return torch.cat(rows)
