"""An interrupted ``lerobot-train`` run continues from its last checkpoint instead of starting again."""

from __future__ import annotations

import json
import shutil

from igen_lerobot.training.config_train import TrainConfig
from igen_lerobot.training.lerobot_train import final_checkpoint, is_finished, last_saved_step, lerobot_train


def _step(checkpoint_dir):
    return json.loads((checkpoint_dir.parent / "training_state" / "training_step.json").read_text())["step"]


def test_a_run_stopped_after_a_checkpoint_resumes_from_it(source_demos, tmp_path):
    out = tmp_path / "bc_rnn"
    # a run of 4 steps that stopped after its step-2 checkpoint looks like a finished 2-step run on disk
    short = TrainConfig(policy_type="bc_rnn", steps=2, batch_size=8, num_workers=0, save_freq=2)
    lerobot_train(short, source_demos, "local/block_grasp_demos", out)
    full = TrainConfig(policy_type="bc_rnn", steps=4, batch_size=8, num_workers=0, save_freq=2)
    assert last_saved_step(out) == 2 and not is_finished(out, full.steps)
    first_weights = (out / "checkpoints" / "000002" / "pretrained_model" / "model.safetensors").read_bytes()

    done = lerobot_train(full, source_demos, "local/block_grasp_demos", out)

    assert is_finished(out, full.steps) and _step(done) == 4
    assert final_checkpoint(out, full.steps) == out / "checkpoints" / "000004" / "pretrained_model"
    # resumed, not restarted: the step-2 checkpoint is the one the first leg wrote, and LeRobot says so
    assert (out / "checkpoints" / "000002" / "pretrained_model" / "model.safetensors").read_bytes() == first_weights
    log = (tmp_path / "bc_rnn.log").read_text()
    assert "'resume': True" in log and "Resuming data order" in log


def test_a_run_without_a_checkpoint_starts_again(source_demos, tmp_path):
    out = tmp_path / "bc_rnn"
    (out / "checkpoints").mkdir(parents=True)  # killed before its first save
    cfg = TrainConfig(policy_type="bc_rnn", steps=2, batch_size=8, num_workers=0)
    done = lerobot_train(cfg, source_demos, "local/block_grasp_demos", out)
    assert _step(done) == 2 and is_finished(out, 2)


def _weights(out, step):
    return (out / "checkpoints" / f"{step:06d}" / "pretrained_model" / "model.safetensors").read_bytes()


def test_a_resumed_run_ends_with_the_weights_of_an_uninterrupted_one(source_demos, tmp_path):
    """Tables resume trainings across sessions, so a resume must not change what the table reports.

    The interruption is made exactly: a finished 4-step run loses its step-4 checkpoint, as a run
    killed between its two saves would, and is brought to step 4 again. Tolerance: none (bytes).
    """
    out = tmp_path / "bc_rnn"
    cfg = TrainConfig(policy_type="bc_rnn", steps=4, batch_size=8, num_workers=0, save_freq=2, seed=3)
    lerobot_train(cfg, source_demos, "local/block_grasp_demos", out)
    uninterrupted = _weights(out, 4)
    assert uninterrupted != _weights(out, 2)  # the last two steps changed the weights

    shutil.rmtree(out / "checkpoints" / "000004")
    (out / "checkpoints" / "last").unlink()
    (out / "checkpoints" / "last").symlink_to("000002")
    assert last_saved_step(out) == 2
    lerobot_train(cfg, source_demos, "local/block_grasp_demos", out)

    assert _weights(out, 4) == uninterrupted
    # and it was a resume, not a second run from scratch (which would match as well)
    assert (tmp_path / "bc_rnn.log").read_text().count("Resuming data order at epoch") == 1


def test_a_run_resumed_after_its_first_epoch_ends_with_the_weights_of_an_uninterrupted_one(source_demos, tmp_path):
    """LeRobot 0.6 with accelerate restarts the data order at epoch 0 on resume (resume_order mends it).

    Batches of 100 make an epoch a few steps long; the run resumes one step into its second epoch
    and ends in its third. Tolerance: none (bytes).
    """
    info = json.loads((source_demos / "meta" / "info.json").read_text())
    per_epoch = -(-info["total_frames"] // 100)
    resume_at = per_epoch + 1
    out = tmp_path / "bc_rnn"
    cfg = TrainConfig(policy_type="bc_rnn", steps=2 * resume_at, batch_size=100, num_workers=0, save_freq=resume_at)
    lerobot_train(cfg, source_demos, "local/block_grasp_demos", out)
    uninterrupted = _weights(out, cfg.steps)

    shutil.rmtree(out / "checkpoints" / f"{cfg.steps:06d}")
    (out / "checkpoints" / "last").unlink()
    (out / "checkpoints" / "last").symlink_to(f"{resume_at:06d}")
    lerobot_train(cfg, source_demos, "local/block_grasp_demos", out)

    assert "Resuming data order at epoch 1, sample 100" in (tmp_path / "bc_rnn.log").read_text()
    assert _weights(out, cfg.steps) == uninterrupted


def test_a_restored_sampler_counts_the_loaders_passes_from_the_epoch_it_was_stopped_in():
    """accelerate calls ``set_epoch(k)`` before its k-th pass, k from 0 in every process."""
    from lerobot.datasets.sampler import EpisodeAwareSampler

    from igen_lerobot.training import resume_order

    assert resume_order.install()

    def sampler() -> EpisodeAwareSampler:
        return EpisodeAwareSampler([0, 7], [7, 20], shuffle=True, seed=5)

    uninterrupted = sampler()
    passes = []
    for k in range(4):
        uninterrupted.set_epoch(k)
        passes.append(list(uninterrupted))
    assert passes[2] != passes[0]

    resumed = sampler()
    resumed.load_state_dict({"epoch": 2, "start_index": 4})
    resumed.set_epoch(0)
    assert list(resumed) == passes[2][4:]
    resumed.set_epoch(1)
    assert list(resumed) == passes[3]
