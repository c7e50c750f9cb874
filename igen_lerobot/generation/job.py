"""Everything one generation worker needs, in one picklable object, and the per-attempt call."""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

from igen_lerobot.core.env_config import TaskEnvConfig
from igen_lerobot.core.seeding import episode_seed
from igen_lerobot.generation.attempt import Attempt
from igen_lerobot.generation.intervengen import IntervenGenConfig, MistakeSource, generate_intervention
from igen_lerobot.generation.mimicgen import MimicGenConfig, generate_demo
from igen_lerobot.generation.sources import SourceLibrary
from igen_lerobot.training.policy_source import PolicySourceConfig, make_base_policy


class GenerationMode(enum.StrEnum):
    """What to generate."""

    MIMICGEN = "mimicgen"  # full demonstrations from source demonstrations
    IGEN = "igen"  # interventions: policy mistakes + replayed recoveries
    IGEN_NO_POLICY = "igen_no_policy"  # ablation: replayed mistakes + replayed recoveries


@dataclass
class GenerationJob:
    """A generation run's fixed inputs; workers rebuild env and policy from it."""

    mode: GenerationMode
    env_config: TaskEnvConfig
    library: SourceLibrary
    run_seed: int
    max_steps: int
    policy: PolicySourceConfig = field(default_factory=PolicySourceConfig)
    mimicgen: MimicGenConfig = field(default_factory=MimicGenConfig)
    igen: IntervenGenConfig = field(default_factory=IntervenGenConfig)


class AttemptRunner:
    """Builds the env (and policy) once, then runs attempts by index."""

    def __init__(self, job: GenerationJob) -> None:
        self.job = job
        self.env = job.env_config.make_task_env()
        self.policy = None
        if job.mode is GenerationMode.IGEN:
            self.policy = make_base_policy(job.policy, job.env_config)

    def __call__(self, attempt: int) -> Attempt:
        seed = episode_seed(self.job.run_seed, attempt)
        if self.job.mode is GenerationMode.MIMICGEN:
            return generate_demo(self.env, self.job.library, self.job.mimicgen, seed, self.job.max_steps)
        mistakes = MistakeSource.POLICY if self.job.mode is GenerationMode.IGEN else MistakeSource.REPLAY
        return generate_intervention(
            self.env, self.policy, self.job.library, self.job.igen, seed, self.job.max_steps, mistakes
        )

    def close(self) -> None:
        self.env.close()
