"""Any :class:`~igen_lerobot.core.task.TaskEnv` as a gymnasium env that ``lerobot-eval`` can roll out.

Observation keys follow LeRobot's env conventions: ``agent_pos`` becomes ``observation.state``,
``environment_state`` becomes ``observation.environment_state`` and, with ``obs_type=pixels_state``,
``pixels/<camera>`` becomes ``observation.images.<camera>`` in LeRobot's preprocessing.
``info["is_success"]`` carries the task's success; an episode terminates on success.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import gymnasium as gym
import numpy as np

from igen_lerobot.core.cameras import render_images
from igen_lerobot.core.task import OBS_ENV_STATE, OBS_STATE

if TYPE_CHECKING:
    from igen_lerobot.core.env_config import TaskEnvConfig


class TaskGymEnv(gym.Env):
    """Gymnasium adapter; the env is seeded per episode through ``reset(seed=...)``."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 20}

    def __init__(
        self,
        config: TaskEnvConfig,
        render_mode: str | None = "rgb_array",
        render_camera: str = "frontview",
        render_size: int = 256,
    ) -> None:
        self.config = config
        self.task_env = config.make_task_env()
        spec = self.task_env.spec
        self.metadata = {**self.metadata, "render_fps": spec.fps}
        self.render_mode = render_mode
        self._render_camera, self._render_size = render_camera, render_size
        self.task_description = spec.instruction
        self.task = spec.name
        inf = np.float32(np.inf)
        spaces = {
            "agent_pos": gym.spaces.Box(-inf, inf, (len(spec.state_names),), np.float32),
            "environment_state": gym.spaces.Box(-inf, inf, (len(spec.env_state_names),), np.float32),
        }
        self._cameras = config.image_cameras
        if self._cameras.cameras:
            size = self._cameras.size
            spaces["pixels"] = gym.spaces.Dict(
                {c: gym.spaces.Box(0, 255, (size, size, 3), np.uint8) for c in self._cameras.cameras}
            )
        self.observation_space = gym.spaces.Dict(spaces)
        low, high = self.task_env.action_bounds()
        self.action_space = gym.spaces.Box(low.astype(np.float32), high.astype(np.float32), dtype=np.float32)

    def _to_gym(self, obs: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        out = {
            "agent_pos": obs[OBS_STATE].astype(np.float32),
            "environment_state": obs[OBS_ENV_STATE].astype(np.float32),
        }
        if self._cameras.cameras:  # the same pixels igen-render writes into datasets
            out["pixels"] = render_images(self.task_env, self._cameras.cameras, self._cameras.size)
        return out

    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        super().reset(seed=seed)
        episode_seed = int(self.np_random.integers(0, 2**31 - 1)) if seed is None else int(seed)
        obs = self.task_env.reset(episode_seed)
        return self._to_gym(obs), {"is_success": False, "episode_seed": episode_seed}

    def step(self, action: np.ndarray):
        info = self.task_env.step(np.asarray(action, dtype=float))
        obs = self._to_gym(self.task_env.observe())
        reward = 1.0 if info.success else 0.0
        return obs, reward, info.success, False, {"is_success": info.success, "contact": info.contact}

    def render(self) -> np.ndarray | None:
        render = getattr(self.task_env, "render", None)
        if render is None:
            return None
        return render(camera=self._render_camera, width=self._render_size, height=self._render_size)

    def close(self) -> None:
        self.task_env.close()
