"""A trained LeRobot policy checkpoint behind our :class:`~igen_lerobot.core.agents.Policy` protocol.

The observation goes through the checkpoint's own saved pre/post-processors (normalisation,
device), exactly as ``lerobot-eval`` does, so a policy sees what it saw in training.
"""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np

from igen_lerobot.core.cameras import IMAGE_PREFIX, CameraConfig, image_key
from igen_lerobot.core.exceptions import ConfigError, TaskMismatchError
from igen_lerobot.core.task import ACTION, OBS_ENV_STATE, OBS_STATE, TaskSpec

logger = logging.getLogger(__name__)


FIX = "train a policy on a dataset of this task (and reveal mode), or run the task the checkpoint was trained on"


def check_policy_features(
    input_features: dict, output_features: dict, spec: TaskSpec, where: str, cameras: CameraConfig | None = None
) -> None:
    """The checkpoint's inputs/outputs are exactly what the task (with ``cameras`` observed) provides."""
    provided = {OBS_STATE: (len(spec.state_names),), OBS_ENV_STATE: (len(spec.env_state_names),)}
    for camera in cameras.cameras if cameras is not None else []:
        provided[image_key(camera)] = (3, cameras.size, cameras.size)  # LeRobot's policies see images CHW
    for key, feature in input_features.items():
        shape = tuple(feature.shape)
        if key not in provided:
            hint = ""
            if key.startswith(f"{IMAGE_PREFIX}.") and len(shape) == 3:
                wanted = [k[len(IMAGE_PREFIX) + 1 :] for k in input_features if k.startswith(f"{IMAGE_PREFIX}.")]
                hint = (
                    f"; a vision checkpoint: run it with --env.obs_type=pixels_state "
                    f"--env.cameras='[{','.join(wanted)}]' --env.image_size={shape[-1]}"
                )
            raise TaskMismatchError(
                f"{where} expects input {key!r} {shape}, which task {spec.name!r} does not provide "
                f"(it provides {', '.join(f'{k} {v}' for k, v in provided.items())}){hint}"
            )
        if shape != provided[key]:
            raise TaskMismatchError(
                f"{where} expects {key} of shape {shape}; task {spec.name!r} gives {provided[key]}: {FIX}"
            )
    action_shape = tuple(output_features[ACTION].shape) if ACTION in output_features else None
    if action_shape != (len(spec.action_names),):
        wanted = (len(spec.action_names),)
        raise TaskMismatchError(
            f"{where} outputs action of shape {action_shape}; task {spec.name!r} takes {wanted}: {FIX}"
        )


def read_checkpoint_config(path: str | Path, spec: TaskSpec, cameras: CameraConfig | None = None):
    """The checkpoint's LeRobot config, checked against ``spec`` and the observed ``cameras`` (no weights loaded)."""
    from lerobot.configs.policies import PreTrainedConfig

    from igen_lerobot.core.plugins import discover_plugins

    # Plugin policy types (bc_rnn) must be registered in every process that loads one,
    # generation workers included, not only in the one that parsed the command line.
    discover_plugins()
    path = Path(path)
    if not (path / "config.json").exists():
        raise ConfigError(
            f"--policy.path={path} has no config.json; point it at a checkpoint's pretrained_model/ folder, "
            "e.g. outputs/train/<run>/checkpoints/last/pretrained_model"
        )
    config = PreTrainedConfig.from_pretrained(path)
    check_policy_features(config.input_features, config.output_features, spec, f"--policy.path={path}", cameras)
    return config


class LeRobotCheckpointPolicy:
    """Loads ``pretrained_model/`` (config, weights, processors) and acts one step at a time."""

    def __init__(
        self, path: str | Path, spec: TaskSpec, device: str = "cpu", cameras: CameraConfig | None = None
    ) -> None:
        import torch
        from lerobot.policies.factory import get_policy_class, make_pre_post_processors

        path = Path(path)
        config = read_checkpoint_config(path, spec, cameras)
        self.image_keys = [k for k in config.input_features if k.startswith(f"{IMAGE_PREFIX}.")]
        config.device = device
        self.policy = get_policy_class(config.type).from_pretrained(path, config=config)
        self.policy.eval()
        overrides = {"device_processor": {"device": device}}
        self.preprocessor, self.postprocessor = make_pre_post_processors(
            config, pretrained_path=str(path), preprocessor_overrides=overrides
        )
        self.instruction = spec.instruction
        self._torch = torch
        self.type = config.type

    def reset(self) -> None:
        self.policy.reset()

    def seed(self, seed: int) -> None:
        """Seed torch's generator, which LeRobot's policies sample from (see ``core.agents.seed_policy``)."""
        self._torch.manual_seed(seed)

    @property
    def steps_trials_together(self) -> bool:
        """Whether :meth:`act_trials` runs.

        It needs a state-only policy that steps a batch of trials exactly as each alone, with draws per
        trial (BC-RNN's LSTM on CPU).
        """
        return not self.image_keys and bool(getattr(self.policy, "trials_batch_exactly", False))

    def start_trials(self, seeds: list[int]) -> None:
        """Start one trial per seed, stepped together by :meth:`act_trials`; trial k draws from its own seed."""
        torch = self._torch
        self.policy.reset()
        self._generators = [torch.Generator().manual_seed(int(seed)) for seed in seeds]

    def act_trials(self, observations: list[dict[str, np.ndarray]]) -> np.ndarray:
        """Actions (B, action_dim) for the trials :meth:`start_trials` began, one observation each.

        Trial k's actions are, bit for bit, what :meth:`act` gives it alone after ``seed(seeds[k])``
        (the normalisers are per element, the policy keeps each row apart): a table's numbers do not
        depend on how trials are grouped.
        """
        torch = self._torch
        batch = {
            OBS_STATE: torch.from_numpy(np.stack([np.asarray(o[OBS_STATE], dtype=np.float32) for o in observations])),
            OBS_ENV_STATE: torch.from_numpy(
                np.stack([np.asarray(o[OBS_ENV_STATE], dtype=np.float32) for o in observations])
            ),
            "task": [self.instruction] * len(observations),
        }
        with torch.inference_mode():
            actions = self.policy.select_action_per_trial(self.preprocessor(batch), self._generators)
            return self.postprocessor(actions).cpu().numpy().astype(float)

    def act(self, observation: dict[str, np.ndarray]) -> np.ndarray:
        torch = self._torch
        batch = {
            OBS_STATE: torch.from_numpy(np.asarray(observation[OBS_STATE], dtype=np.float32))[None],
            OBS_ENV_STATE: torch.from_numpy(np.asarray(observation[OBS_ENV_STATE], dtype=np.float32))[None],
            "task": [self.instruction],
        }
        for key in self.image_keys:  # (H, W, 3) uint8 -> (1, 3, H, W) float in [0, 1], as lerobot-eval does
            image = torch.from_numpy(np.ascontiguousarray(observation[key]))
            batch[key] = (image.permute(2, 0, 1).float() / 255.0)[None]
        with torch.inference_mode():
            action = self.postprocessor(self.policy.select_action(self.preprocessor(batch)))
        return action[0].cpu().numpy().astype(float)
