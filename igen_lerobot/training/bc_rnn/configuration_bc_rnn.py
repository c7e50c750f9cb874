"""Config of BC-RNN (``--policy.type=bc_rnn``): robomimic's low-dim BC-RNN defaults.

The IntervenGen paper trains every policy with robomimic's default BC-RNN hyperparameters
except a learning rate of 1e-3 (as MimicGen does): a 2-layer LSTM with 400 hidden units over
sequences of 10 steps, a 5-mode Gaussian-mixture action head (softplus std, min std 1e-4,
low-noise sampling at evaluation), Adam without weight decay. At rollout the LSTM state is reset
every ``horizon`` steps, as robomimic does.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from lerobot.configs import FeatureType, NormalizationMode, PreTrainedConfig
from lerobot.optim.optimizers import AdamConfig
from lerobot.optim.schedulers import CosineAnnealingWithWarmupSchedulerConfig

from igen_lerobot.core.exceptions import ConfigError

LR_SCHEDULES = ("constant", "cosine")


@PreTrainedConfig.register_subclass("bc_rnn")
@dataclass
class BCRNNConfig(PreTrainedConfig):
    """BC-RNN hyperparameters (robomimic ``bc_rnn`` low-dim defaults, lr 1e-3, annealed by a cosine schedule)."""

    n_obs_steps: int = 1
    horizon: int = 10  # training sequence length and rollout RNN reset period (robomimic seq_length)
    rnn_type: str = "LSTM"  # LSTM or GRU
    rnn_hidden_dim: int = 400
    rnn_num_layers: int = 2
    mlp_dims: tuple[int, ...] = ()  # optional MLP between the RNN and the head (robomimic: none)
    gmm_num_modes: int = 5
    gmm_min_std: float = 1e-4
    low_noise_eval: bool = True  # sample with std 1e-4 at evaluation (robomimic)
    normalization_mapping: dict[str, NormalizationMode] = field(
        default_factory=lambda: {
            "STATE": NormalizationMode.MEAN_STD,
            "ENV": NormalizationMode.MEAN_STD,
            "ACTION": NormalizationMode.MIN_MAX,  # the GMM means are tanh-squashed into [-1, 1]
        }
    )
    # [input units] added to every mean/std-normalised input's std (robomimic adds 1e-3 when it
    # normalises). Without it, an input that never varies in the data (a fixed peg's height) gets
    # std ~0 and any deviation at test time is multiplied by ~1e8.
    obs_std_tolerance: float = 0.0
    # [input units] the std given to an input that never varies in the data (std or range < 1e-6); 0 keeps its
    # ~0 std. 1.0 passes its deviations through in their own units (a flag's 0 -> 1, a height error
    # in metres), as robomimic's unnormalised inputs do; inputs that vary keep mean/std. With LeRobot's
    # ~0 std, a 0.5 mm error on a fixed peg's height made the Nut Insertion base policy drop the nut
    # at the first step (docs/results.md, "Why the base policy lets go"); a no-op where no input is
    # constant (Block Grasp).
    constant_input_std: float = 1.0
    # a dataset root whose observation statistics normalise the inputs instead of the training data's own
    # (the actions keep the training data's). igen-table gives every row the base dataset D's, so rows
    # differ only in their data: with its own, a row whose few added episodes are the only frames where
    # an input varies (a peg's height under error) gets a tiny std from them, and that input's deviations
    # reach the network as tens of standard deviations (docs/results.md, "One normaliser for every row")
    observation_stats: str | None = None
    optimizer_lr: float = 1e-3
    optimizer_weight_decay: float = 0.0
    optimizer_grad_clip_norm: float = 1e6  # robomimic does not clip gradients
    # "cosine" anneals the rate to zero over lerobot-train's --steps, so the last checkpoints stop swinging
    # with the last batches; "constant" is robomimic's. Cosine is the default since the schedule study
    # (docs/results.md, reproducibility: Nut Insertion I-Gen, 3 training seeds, held-out test trials
    # 29% against 17%, validation overstating the test by 6 points against 12, last swing 2 against 12)
    lr_schedule: str = "cosine"

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.rnn_type not in ("LSTM", "GRU"):
            raise ConfigError(f"policy.rnn_type must be LSTM or GRU, got {self.rnn_type!r}")
        if self.horizon < 1:
            raise ConfigError(f"policy.horizon must be >= 1, got {self.horizon}")
        if self.gmm_num_modes < 1:
            raise ConfigError(f"policy.gmm_num_modes must be >= 1, got {self.gmm_num_modes}")
        if self.lr_schedule not in LR_SCHEDULES:
            raise ConfigError(f"policy.lr_schedule must be one of {list(LR_SCHEDULES)}, got {self.lr_schedule!r}")
        if self.constant_input_std < 0:
            raise ConfigError(f"policy.constant_input_std must be >= 0, got {self.constant_input_std}")
        if self.obs_std_tolerance < 0:
            raise ConfigError(f"policy.obs_std_tolerance must be >= 0, got {self.obs_std_tolerance}")
        if self.n_obs_steps != 1:
            raise ConfigError("policy.n_obs_steps must be 1 for bc_rnn (the RNN carries the history)")

    def get_optimizer_preset(self) -> AdamConfig:
        return AdamConfig(
            lr=self.optimizer_lr, weight_decay=self.optimizer_weight_decay, grad_clip_norm=self.optimizer_grad_clip_norm
        )

    def get_scheduler_preset(self) -> CosineAnnealingWithWarmupSchedulerConfig | None:
        if self.lr_schedule == "cosine":
            return CosineAnnealingWithWarmupSchedulerConfig(num_warmup_steps=0)
        return None

    def validate_features(self) -> None:
        low_dim = [k for k, f in self.input_features.items() if f.type in (FeatureType.STATE, FeatureType.ENV)]
        if not low_dim:
            raise ConfigError(
                "bc_rnn needs at least one low-dimensional input (observation.state or observation.environment_state)"
            )
        if self.image_features:
            raise ConfigError(f"bc_rnn is a low-dim policy; drop the image inputs {sorted(self.image_features)}")
        if self.action_feature is None:
            raise ConfigError("bc_rnn needs an 'action' output feature")

    @property
    def observation_delta_indices(self) -> list[int]:
        return list(range(self.horizon))

    @property
    def action_delta_indices(self) -> list[int]:
        return list(range(self.horizon))

    @property
    def reward_delta_indices(self) -> None:
        return None
