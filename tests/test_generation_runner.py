"""Parallel, reproducible, resumable generation: workers, kills, Ctrl-C, Ray, merging, the CLI."""

import multiprocessing as mp
import os
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from igen_lerobot.core.exceptions import TaskMismatchError
from igen_lerobot.datasets.merge import merge_datasets
from igen_lerobot.datasets.reader import load_episodes, read_igen_meta
from igen_lerobot.datasets.spool import EpisodeSpool
from igen_lerobot.datasets.writer import DatasetBuilder
from igen_lerobot.generation.job import GenerationJob, GenerationMode
from igen_lerobot.generation.runner import run_generation
from igen_lerobot.generation.sources import parse_interventions

N = 6


@pytest.fixture(scope="module")
def job(block_grasp_config, source_interventions):
    env = block_grasp_config.make_task_env()
    library = parse_interventions(
        load_episodes(source_interventions, env.spec), env.spec, env.target_pose_from_action, env.gripper_command
    )
    env.close()
    return GenerationJob(
        mode=GenerationMode.IGEN, env_config=block_grasp_config, library=library, run_seed=11, max_steps=200
    )


@pytest.fixture(scope="module")
def reference(job, tmp_path_factory):
    spool = EpisodeSpool(tmp_path_factory.mktemp("ref") / "attempts")
    stats = run_generation(job, spool, N, workers=1)
    assert stats.kept >= N
    return spool


def first_kept(spool, n=N):
    return [(attempt, episode) for attempt, episode in spool.iter_kept(n)]


def assert_same_episodes(a, b):
    assert [x for x, _ in a] == [y for y, _ in b]
    for (_, ea), (_, eb) in zip(a, b, strict=True):
        assert ea.seed == eb.seed
        np.testing.assert_array_equal(ea.action, eb.action)
        np.testing.assert_array_equal(ea.is_intervention, eb.is_intervention)


def test_two_workers_give_the_same_dataset_as_one(job, reference, tmp_path):
    import resource

    def children_cpu() -> float:
        usage = resource.getrusage(resource.RUSAGE_CHILDREN)
        return usage.ru_utime + usage.ru_stime

    spool = EpisodeSpool(tmp_path / "attempts")
    before = children_cpu()
    stats = run_generation(job, spool, N, workers=2)
    assert stats.kept >= N and stats.success_rate > 0.5
    assert_same_episodes(first_kept(spool), first_kept(reference))
    # the recorded counts too: only those up to the dataset's last kept attempt, whatever ran past it
    ours, theirs = spool.outcome(N), reference.outcome(N)
    assert (ours.attempted, ours.kept, ours.dropped) == (theirs.attempted, theirs.kept, theirs.dropped)
    assert ours.attempted == spool.kept_attempts()[N - 1] + 1
    # the workers' CPU time reaches this process once the run ends (a table step records it as its cost);
    # at least the simulation they did, most of the run's wall time
    assert children_cpu() - before > 0.5 * stats.seconds > 0


def test_the_outcome_counts_only_attempts_up_to_the_last_kept_one(reference, tmp_path):
    spool = EpisodeSpool(tmp_path / "attempts")
    episode = reference.load(reference.kept_attempts()[0])
    for attempt in (0, 2, 5, 7):
        spool.keep(attempt, episode)
    for attempt, reason in ((1, "failed"), (3, "failed"), (4, "no_mistake"), (6, "failed"), (8, "failed")):
        spool.reject(attempt, reason)
    outcome = spool.outcome(3)  # the dataset is attempts 0, 2 and 5
    assert (outcome.attempted, outcome.kept, outcome.run_past_the_last) == (6, 3, 3)
    assert outcome.dropped == {"failed": 2, "no_mistake": 1}
    assert outcome.success_rate == pytest.approx(0.5)


def test_a_killed_worker_is_replaced_and_nothing_is_lost(job, reference, tmp_path):
    spool = EpisodeSpool(tmp_path / "attempts")
    killed = []

    def kill_a_worker(attempt, result):
        if not killed:
            victim = mp.active_children()[0]
            os.kill(victim.pid, signal.SIGKILL)
            killed.append(victim.pid)

    stats = run_generation(job, spool, N, workers=2, on_result=kill_a_worker)
    assert killed and stats.respawned_workers >= 1
    assert_same_episodes(first_kept(spool), first_kept(reference))
    assert not list(spool.directory.glob("*.tmp"))


def test_ctrl_c_then_rerun_resumes_to_the_same_dataset(job, reference, tmp_path):
    spool_dir = tmp_path / "attempts"

    def interrupt(attempt, result, seen=[]):  # noqa: B006 - counts calls within this run
        seen.append(attempt)
        if len(seen) == 2:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        run_generation(job, EpisodeSpool(spool_dir), N, workers=2, on_result=interrupt)
    assert not mp.active_children(), "workers must not outlive an interrupted run"
    partial = EpisodeSpool(spool_dir)
    assert 2 <= len(partial.done_attempts()) < N + 4
    stats = run_generation(job, partial, N, workers=2)
    assert stats.resumed_attempts >= 2
    assert_same_episodes(first_kept(partial), first_kept(reference))


def test_ray_backend_on_a_local_cluster_matches_local(job, reference, tmp_path):
    import ray  # the 'ray' extra is part of the locked environment (scripts/setup.sh installs it)

    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        spool = EpisodeSpool(tmp_path / "attempts")
        stats = run_generation(job, spool, N, workers=2, backend="ray")
    finally:
        ray.shutdown()
    assert stats.kept >= N
    assert_same_episodes(first_kept(spool), first_kept(reference))


def test_merge_keeps_flags_and_metadata(job, reference, source_demos, tmp_path):
    spec = job.env_config.task_spec
    builder = DatasetBuilder(tmp_path / "generated", "local/generated", spec)
    for attempt, episode in first_kept(reference):
        builder.spool.keep(attempt, episode)
    builder.finalize(N, metadata={"created_by": "test", "mode": "igen"})
    merged = merge_datasets([source_demos, tmp_path / "generated"], tmp_path / "merged", "local/merged", spec)

    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    ds = LeRobotDataset("local/merged", root=merged)
    demos = load_episodes(source_demos, spec)
    assert ds.num_episodes == len(demos) + N
    episodes = load_episodes(merged, spec)
    assert [e.kind for e in episodes] == ["demo"] * len(demos) + ["igen"] * N
    assert not any(e.is_intervention.any() for e in episodes[: len(demos)])
    assert all(e.is_intervention.all() for e in episodes[len(demos) :])
    assert read_igen_meta(merged).meta["episode_kinds"] == {"demo": len(demos), "igen": N}
    import dataclasses

    with pytest.raises(TaskMismatchError):
        merge_datasets(
            [source_demos, tmp_path / "generated"],
            tmp_path / "m2",
            "local/m2",
            dataclasses.replace(spec, name="nut_insertion"),
        )


def test_igen_generate_cli_end_to_end(source_interventions, source_demos, tmp_path):
    out = tmp_path / "gen"
    cmd = [
        str(Path(sys.executable).parent / "igen-generate"),
        "--mode=igen",
        "--task=block_grasp",
        f"--source.root={source_interventions}",
        "--num_episodes=3",
        "--workers=2",
        "--seed=4",
        f"--dataset.root={out}",
        f"--merge_with={source_demos}",
    ]
    result = subprocess.run(
        cmd, capture_output=True, text=True, timeout=300, env={**os.environ, "MUJOCO_GL": "egl", "HF_HUB_OFFLINE": "1"}
    )
    assert result.returncode == 0, result.stderr[-3000:]
    assert "generation success rate" in result.stdout and "mean kept episode length" in result.stdout
    spec_eps = load_episodes(out, __import__("lerobot_env_igen").block_grasp.spec.SPEC)
    assert len(spec_eps) == 3 and all(e.kind == "igen" for e in spec_eps)
    assert (tmp_path / "gen_merged" / "meta" / "igen.json").exists()
    bad = subprocess.run(
        cmd[:3] + ["--source.root=" + str(source_demos), "--num_episodes=1", f"--dataset.root={tmp_path / 'bad'}"],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "MUJOCO_GL": "egl"},
    )
    assert bad.returncode == 2 and "no intervention frames" in bad.stderr


def test_worker_processes_load_a_plugin_policy_checkpoint(job, bc_rnn_checkpoint, tmp_path):
    """Each worker registers LeRobot plugins itself before loading the bc_rnn checkpoint."""
    import dataclasses

    from igen_lerobot.training.policy_source import PolicySourceConfig

    with_policy = dataclasses.replace(job, policy=PolicySourceConfig(path=str(bc_rnn_checkpoint)), max_steps=320)
    spool = EpisodeSpool(tmp_path / "attempts")
    stats = run_generation(with_policy, spool, 2, workers=2)
    assert stats.kept >= 2
    assert not any(reason.startswith("error") for reason in stats.reasons)


def test_a_job_whose_workers_cannot_start_stops_with_their_error(job, tmp_path):
    import dataclasses

    from igen_lerobot.generation.runner import GenerationSetupError
    from igen_lerobot.training.policy_source import PolicySourceConfig

    broken = dataclasses.replace(job, policy=PolicySourceConfig(path=str(tmp_path / "no_such_checkpoint")))
    with pytest.raises(GenerationSetupError, match="has no config.json"):
        run_generation(broken, EpisodeSpool(tmp_path / "attempts"), 2, workers=2)
    assert not mp.active_children()
