"""igen-eval: seeded trials, confidence intervals, checkpoint selection, bad input."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.evaluation.checkpoints import best_result, list_checkpoints
from igen_lerobot.evaluation.trials import EvalResult, evaluate, wilson_interval

BIN = Path(sys.executable).parent
ENV = {**os.environ, "MUJOCO_GL": "egl", "HF_HUB_OFFLINE": "1"}


@pytest.mark.parametrize(
    ("successes", "trials", "expected"),
    # reference values of the 95% Wilson score interval (z = 1.96)
    [(0, 50, (0.0, 0.0713)), (50, 50, (0.9287, 1.0)), (25, 50, (0.3664, 0.6336)), (3, 10, (0.1078, 0.6032))],
)
def test_wilson_interval_matches_reference_values(successes, trials, expected):
    low, high = wilson_interval(successes, trials)
    assert low == pytest.approx(expected[0], abs=1e-3)
    assert high == pytest.approx(expected[1], abs=1e-3)


def test_wilson_interval_needs_a_trial():
    with pytest.raises(ConfigError, match="at least one trial"):
        wilson_interval(0, 0)


def _fake_run(root: Path, steps: list[int]) -> Path:
    """The checkpoint layout lerobot-train writes: checkpoints/<step:06d>/pretrained_model/config.json."""
    for step in steps:
        model = root / "checkpoints" / f"{step:06d}" / "pretrained_model"
        model.mkdir(parents=True)
        (model / "config.json").write_text("{}")
    (root / "checkpoints" / "000099").mkdir()  # an unfinished checkpoint: no pretrained_model yet
    return root


def test_every_kth_checkpoint_and_always_the_last(tmp_path):
    run = _fake_run(tmp_path / "run", [2, 4, 6, 8, 10])
    assert [s for s, _ in list_checkpoints(run, every=1)] == [2, 4, 6, 8, 10]
    assert [s for s, _ in list_checkpoints(run, every=2)] == [4, 8, 10]
    assert [s for s, _ in list_checkpoints(run, every=3)] == [6, 10]
    with pytest.raises(ConfigError, match="no checkpoints/ folder"):
        list_checkpoints(tmp_path / "nothing")


def test_best_checkpoint_is_the_highest_rate_ties_to_the_later():
    def result(step, rate):
        return EvalResult("p", 10, int(rate * 10), rate, (0, 1), 1.0, 0.0, step=step)

    assert best_result([result(1, 0.2), result(2, 0.6), result(3, 0.4)]).step == 2
    assert best_result([result(1, 0.6), result(2, 0.6)]).step == 2


def test_seeded_trials_are_reproducible(block_grasp_config, block_grasp_env):
    policy = block_grasp_config.make_scripted_policy()
    first = evaluate(block_grasp_env, policy, "scripted", 4, seed=7, max_steps=200, progress=False)
    again = evaluate(block_grasp_env, policy, "scripted", 4, seed=7, max_steps=200, progress=False)
    assert first.per_trial == again.per_trial
    assert first.successes == sum(first.per_trial)
    assert first.success_rate == pytest.approx(first.successes / 4)
    assert first.mean_steps == again.mean_steps


def test_igen_eval_evaluates_a_lerobot_train_run(bc_rnn_checkpoint, tmp_path):
    train_dir = bc_rnn_checkpoint.parents[2]  # .../<run>/checkpoints/last/pretrained_model
    out = tmp_path / "eval.json"
    result = subprocess.run(
        [str(BIN / "igen-eval"), "--task=block_grasp", f"--train_dir={train_dir}", "--n_trials=2", f"--output={out}"],
        capture_output=True,
        text=True,
        timeout=300,
        env=ENV,
    )
    assert result.returncode == 0, result.stderr[-3000:]
    report = json.loads(out.read_text())
    assert report["n_trials"] == 2 and report["corruption"]["type"] == "box"
    [only] = report["results"]
    assert only["step"] == 3 and only["trials"] == 2 and len(only["per_trial"]) == 2
    assert report["best"]["step"] == 3
    assert "step 3:" in result.stdout and "95% CI" in result.stdout


def test_a_report_gives_back_the_config_its_trials_ran_under(block_grasp_config):
    from igen_lerobot.evaluation.evaluate import error_model_record, report_env_config

    record = error_model_record(block_grasp_config.corruption)
    report = {"task": "block_grasp", "reveal": "full", "corruption": record}
    config = report_env_config(report)
    assert config.type == "block_grasp" and str(config.reveal) == "full"
    assert error_model_record(config.corruption) == json.loads(json.dumps(record))
    other = {**record, next(k for k in record if k != "type"): "changed"}
    with pytest.raises(ConfigError, match="corruption .* default error model"):
        report_env_config({**report, "corruption": other})


def test_igen_eval_bad_input_names_the_fix(tmp_path):
    run = subprocess.run(
        [str(BIN / "igen-eval"), "--task=block_grasp", f"--train_dir={tmp_path}"],
        capture_output=True,
        text=True,
        timeout=300,
        env=ENV,
    )
    assert run.returncode == 2
    assert "no checkpoints/ folder" in run.stderr and "--train_dir" in run.stderr
    both = subprocess.run(
        [str(BIN / "igen-eval"), "--task=block_grasp", f"--train_dir={tmp_path}", f"--policy.path={tmp_path}"],
        capture_output=True,
        text=True,
        timeout=300,
        env=ENV,
    )
    assert both.returncode == 2 and "not both" in both.stderr


class _Recording:
    """The policy under test, keeping every action it returns."""

    def __init__(self, policy) -> None:
        self.policy, self.actions = policy, []

    def reset(self) -> None:
        self.policy.reset()

    def seed(self, seed: int) -> None:
        self.policy.seed(seed)

    def act(self, observation):
        action = self.policy.act(observation)
        self.actions.append(action)
        return action


def test_a_sampling_checkpoints_trial_is_the_same_whatever_ran_before(bc_rnn_checkpoint, block_grasp_config):
    """BC-RNN's mixture head draws a mode every step from torch's generator; each trial seeds it from its
    own seed, so trial i repeats exactly (tolerance 0) after other trials or in another process (a
    rehearsal's trial i is igen-eval's trial i)."""
    import numpy as np
    import torch

    from igen_lerobot.evaluation.trials import rollout
    from igen_lerobot.training.policy_source import PolicySourceConfig, make_base_policy

    policy = _Recording(make_base_policy(PolicySourceConfig(path=str(bc_rnn_checkpoint)), block_grasp_config))
    env = block_grasp_config.make_task_env()
    try:
        observation = env.reset(7)
        drawn = []
        for generator_seed in range(5):  # the policy does sample: unseeded, trials would differ
            torch.manual_seed(generator_seed)
            policy.reset()
            drawn.append(policy.act(observation))
        assert any(not np.array_equal(drawn[0], other) for other in drawn[1:])

        policy.actions.clear()
        rollout(env, policy, seed=7, max_steps=15)
        first = np.stack(policy.actions)
        torch.rand(1000)  # whatever else used the generator in between
        rollout(env, policy, seed=8, max_steps=15)
        policy.actions.clear()
        rollout(env, policy, seed=7, max_steps=15)
        np.testing.assert_array_equal(np.stack(policy.actions), first)
    finally:
        env.close()


def test_trials_over_worker_processes_match_one_process(block_grasp_config, block_grasp_env):
    """``--workers=2`` gives each trial the outcome and step count one process gives (tolerance 0):
    trial i is run from its own seed whichever worker takes it, and results come back in trial order."""
    from igen_lerobot.evaluation.parallel import TrialPool
    from igen_lerobot.training.policy_source import PolicySourceConfig

    here = evaluate(
        block_grasp_env, block_grasp_config.make_scripted_policy(), "scripted", 6, seed=7, max_steps=200, progress=False
    )
    assert len(set(here.per_trial_steps)) > 1  # trials end at different steps: a shuffled order would show
    with TrialPool(block_grasp_config, workers=2) as pool:
        spread = pool.evaluate(PolicySourceConfig(), "scripted", 6, seed=7, max_steps=200, progress=False)
        again = pool.evaluate(PolicySourceConfig(), "scripted", 3, seed=8, max_steps=200, progress=False)
    assert spread.per_trial == here.per_trial and spread.per_trial_steps == here.per_trial_steps
    assert spread.successes == here.successes and spread.mean_steps == here.mean_steps
    other = evaluate(
        block_grasp_env, block_grasp_config.make_scripted_policy(), "scripted", 3, seed=8, max_steps=200, progress=False
    )
    assert again.per_trial_steps == other.per_trial_steps  # a second target in the same pool: its own seeds


def test_the_workers_cpu_time_counts_as_this_processs_childrens():
    """A table step's cost is its process's children's CPU time; workers forked from multiprocessing's
    fork server are the server's children, so the pool must reap the server for their time to count."""
    import resource
    import time

    from igen_lerobot.core.env_config import task_config_class
    from igen_lerobot.evaluation.parallel import TrialPool
    from igen_lerobot.training.policy_source import PolicySourceConfig, make_base_policy

    def children_cpu() -> float:
        usage = resource.getrusage(resource.RUSAGE_CHILDREN)
        return usage.ru_utime + usage.ru_stime

    config = task_config_class("block_grasp")()
    before = children_cpu()
    with TrialPool(config, workers=2) as pool:
        result = pool.evaluate(PolicySourceConfig(), "scripted", 6, seed=7, max_steps=200, progress=False)
    spent = children_cpu() - before

    # the same trials in this process: the CPU their simulation costs, whatever else runs on the machine
    # (a bound on wall time failed beside two trainings, when the trials waited for a core)
    env, policy = config.make_task_env(), make_base_policy(PolicySourceConfig(), config)
    started = time.process_time()
    here = evaluate(env, policy, "scripted", 6, seed=7, max_steps=200, progress=False)
    simulation = time.process_time() - started
    env.close()
    assert here.per_trial == result.per_trial
    # the workers ran that simulation (and their start-up on top): tolerance, half of it
    assert spent > 0.5 * simulation > 0, (spent, simulation)


def test_a_checkpoints_actions_are_the_same_at_one_torch_thread_as_at_two(bc_rnn_checkpoint, block_grasp_config):
    """Evaluation workers run torch at one thread; a sampling BC-RNN checkpoint must act bit for bit as it
    does at two (tolerance 0), or ``--workers`` would change a table's numbers."""
    import numpy as np
    import torch

    from igen_lerobot.evaluation.trials import rollout
    from igen_lerobot.training.policy_source import PolicySourceConfig, make_base_policy

    policy = _Recording(make_base_policy(PolicySourceConfig(path=str(bc_rnn_checkpoint)), block_grasp_config))
    env = block_grasp_config.make_task_env()
    threads = torch.get_num_threads()
    actions = {}
    try:
        for n in (2, 1):
            torch.set_num_threads(n)
            policy.actions.clear()
            rollout(env, policy, seed=7, max_steps=30)
            actions[n] = np.stack(policy.actions)
    finally:
        torch.set_num_threads(threads)
        env.close()
    np.testing.assert_array_equal(actions[1], actions[2])


def test_igen_eval_workers_bad_input_names_the_fix():
    from igen_lerobot.evaluation.config_eval import EvalConfig
    from igen_lerobot.viz.rerun_log import RerunConfig

    with pytest.raises(ConfigError, match="--workers must be >= 1"):
        EvalConfig(task="block_grasp", workers=0)
    with pytest.raises(ConfigError, match="--trials_together must be >= 1"):
        EvalConfig(task="block_grasp", trials_together=0)
    with pytest.raises(ConfigError, match="--workers=1"):
        EvalConfig(task="block_grasp", workers=2, rerun=RerunConfig(mode="save", path="x.rrd"))


def test_trials_stepped_together_act_as_each_trial_alone(bc_rnn_checkpoint, block_grasp_config):
    """``--trials_together``: one batched BC-RNN call per step for a group of trials must give each trial,
    bit for bit (tolerance 0), the actions it gets alone after seeding from its own seed, whatever the
    group's size and the trials beside it; otherwise grouping would change a table's numbers."""
    import numpy as np

    from igen_lerobot.evaluation.trials import rollout, rollout_together, steps_trials_together
    from igen_lerobot.training.policy_source import PolicySourceConfig, make_base_policy

    policy = make_base_policy(PolicySourceConfig(path=str(bc_rnn_checkpoint)), block_grasp_config)
    assert steps_trials_together(policy)
    envs = [block_grasp_config.make_task_env() for _ in range(3)]
    seeds, steps = [7, 8, 9], 25  # past BC-RNN's 10-step horizon, where its memory is reset
    try:
        alone = {}
        for seed in seeds:
            recording = _Recording(policy)
            rollout(envs[0], recording, seed, steps)
            alone[seed] = np.stack(recording.actions)
        for group in ([7, 8, 9], [9, 7], [8]):
            rows: list[list[np.ndarray]] = [[] for _ in group]
            act_trials = policy.act_trials

            def recorded(observations, rows=rows, act_trials=act_trials):
                actions = act_trials(observations)
                for row, action in zip(rows, actions, strict=True):
                    row.append(action)
                return actions

            policy.act_trials = recorded
            try:
                outcomes = rollout_together(envs[: len(group)], policy, group, steps)
            finally:
                del policy.act_trials
            assert outcomes == [(False, steps)] * len(group)  # a 3-step policy does not grasp
            for seed, row in zip(group, rows, strict=True):
                np.testing.assert_array_equal(np.stack(row), alone[seed])
    finally:
        for env in envs:
            env.close()


class _StepsTogether:
    """The scripted policy behind the grouped interface: trials that end at different steps."""

    steps_trials_together = True

    def __init__(self, policy) -> None:
        self.policy = policy

    def start_trials(self, seeds) -> None:
        self.policy.reset()

    def act_trials(self, observations):
        import numpy as np

        return np.stack([self.policy.act(observation) for observation in observations])


def test_a_group_of_trials_ends_each_one_where_it_ends_alone(block_grasp_config, block_grasp_env):
    """Trials of one group succeed at different steps; each keeps its own outcome and step count (tolerance
    0), in trial order, through evaluate() and through the worker pool."""
    from igen_lerobot.evaluation.parallel import TrialPool
    from igen_lerobot.training.policy_source import PolicySourceConfig

    scripted = block_grasp_config.make_scripted_policy()
    alone = evaluate(block_grasp_env, scripted, "scripted", 7, seed=7, max_steps=200, progress=False)
    assert len(set(alone.per_trial_steps)) > 1
    grouped = evaluate(
        block_grasp_env,
        _StepsTogether(scripted),
        "scripted",
        7,
        seed=7,
        max_steps=200,
        progress=False,
        together=3,
        make_env=block_grasp_config.make_task_env,
    )
    assert grouped.per_trial == alone.per_trial and grouped.per_trial_steps == alone.per_trial_steps
    with TrialPool(block_grasp_config, workers=2) as pool:  # the scripted policy runs one trial at a time
        spread = pool.evaluate(PolicySourceConfig(), "scripted", 7, seed=7, max_steps=200, progress=False, together=3)
        # a policy that cannot step trials together is shared out one trial at a time, for balance
        assert pool.trial_groups(PolicySourceConfig(), 7, together=3) == [[i] for i in range(7)]
    assert spread.per_trial_steps == alone.per_trial_steps


def test_a_checkpoints_trials_in_worker_groups_match_one_process(bc_rnn_checkpoint, block_grasp_config):
    """The pool steps a BC-RNN checkpoint's trials in groups: the same outcomes as one process, one by one."""
    from igen_lerobot.evaluation.parallel import TrialPool
    from igen_lerobot.training.policy_source import PolicySourceConfig, make_base_policy

    source = PolicySourceConfig(path=str(bc_rnn_checkpoint))
    env = block_grasp_config.make_task_env()
    try:
        policy = make_base_policy(source, block_grasp_config)
        alone = evaluate(env, policy, "ckpt", 5, seed=3, max_steps=30, progress=False)
    finally:
        env.close()
    with TrialPool(block_grasp_config, workers=2) as pool:
        grouped = pool.evaluate(source, "ckpt", 5, seed=3, max_steps=30, progress=False, together=3)
        assert max(map(len, pool.trial_groups(source, 5, together=3))) > 1
    assert grouped.per_trial == alone.per_trial and grouped.per_trial_steps == alone.per_trial_steps


def test_trial_groups_cover_every_trial_once_in_balanced_groups():
    from igen_lerobot.evaluation.trials import trial_groups

    for trials, workers, together in [(50, 2, 10), (50, 2, 25), (7, 2, 3), (1, 2, 10), (5, 1, 1)]:
        groups = trial_groups(trials, workers, together)
        assert [i for group in groups for i in group] == list(range(trials))
        assert max(map(len, groups)) <= together and max(map(len, groups)) - min(map(len, groups)) <= 1
    assert [len(g) for g in trial_groups(50, 2, 10)] == [8, 9, 8, 8, 9, 8]  # 6 groups: 3 per worker
