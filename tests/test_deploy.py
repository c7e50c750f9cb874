"""The deployment loop on the simulated arm: observations as in training, sim success preserved,
and every fault ends in a stopped arm with a clear reason."""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np
import pytest

from igen_lerobot.core.belief import Reveal
from igen_lerobot.core.exceptions import ConfigError
from igen_lerobot.core.seeding import episode_seed
from igen_lerobot.evaluation.trials import evaluate
from lerobot_robot_igen.arm.config_arm import ArmBackendConfig
from lerobot_robot_igen.arm.driver import ConnectionLostError, DriverError
from lerobot_robot_igen.arm.mujoco_arm import MujocoArm
from lerobot_robot_igen.arm.safe_arm import SafeArm
from lerobot_robot_igen.arm.safety import SafetyLimits
from lerobot_robot_igen.deploy.belief import cube_belief
from lerobot_robot_igen.deploy.config_deploy import (
    DeployConfig,
    RealSensePerceptionConfig,
    SimArmBackendConfig,
    TruthPerceptionConfig,
)
from lerobot_robot_igen.deploy.loop import LoopSettings, run_episode
from lerobot_robot_igen.deploy.trials import deploy
from lerobot_robot_igen.perception.cube_pose import CubeNotVisibleError, PoseRejectedError
from lerobot_robot_igen.perception.pose_source import SimTruthPose

SEED = 1_000_003


@pytest.fixture
def sim_arm():
    arm = MujocoArm()
    arm.connect()
    yield arm
    arm.disconnect()


def scripted_policy():
    from lerobot_env_igen.block_grasp.scripted import ScriptedGraspPolicy

    return ScriptedGraspPolicy()


def run(arm, policy, poses=None, settings=None, seed=SEED, limits=None, on_step=None, watchdog=False):
    arm.reset_scene(seed)
    safe = SafeArm(arm, arm.world_from_base, limits or SafetyLimits(), watchdog=watchdog)
    belief = cube_belief(arm.env.corruption, Reveal.FULL)
    settings = settings or LoopSettings(realtime=False, contact_force_threshold=0.0)
    try:
        outcome = run_episode(
            safe, poses or SimTruthPose(arm), policy, belief, settings, lambda s, a: arm.task_success(), on_step
        )
    finally:
        safe.close()
    return outcome, safe


def test_observation_is_built_exactly_as_in_training(sim_arm, block_grasp_config):
    """Same scene, same pose error, same policy: the loop's observations are BlockGraspEnv's."""
    env = block_grasp_config.make_task_env()
    env_obs = []
    policy = scripted_policy()
    env.reset(SEED)
    policy.reset()
    obs = env.observe()
    for _ in range(60):
        env_obs.append(obs)
        env.step(policy.act(obs))
        obs = env.observe()
    env.close()

    loop_obs = []
    outcome, _ = run(
        sim_arm,
        scripted_policy(),
        settings=LoopSettings(realtime=False, max_steps=60, contact_force_threshold=0.0),
        on_step=lambda rec: loop_obs.append(rec.observation),
    )
    assert outcome.fault is None
    first_contact = next(i for i, o in enumerate(env_obs) if o["observation.environment_state"][7] > 0)
    assert first_contact > 5
    for i in range(first_contact):  # identical inputs until the first touch (tolerance: float32 rounding)
        for key in ("observation.state", "observation.environment_state"):
            np.testing.assert_allclose(loop_obs[i][key], env_obs[i][key], atol=1e-6, err_msg=f"{key} at step {i}")
    # contact comes from the force on the hand (as on a real arm), not from geom pairs: same step
    assert loop_obs[first_contact]["observation.environment_state"][7] == 1.0
    assert loop_obs[first_contact]["observation.environment_state"][8] == 1.0


def test_rehearsal_preserves_the_policys_sim_success(block_grasp_config):
    """Trial i of the rehearsal is igen-eval's trial i; outcomes agree trial by trial (tolerance: 1 of 6)."""
    cfg = DeployConfig(robot=SimArmBackendConfig(), perception=TruthPerceptionConfig(), trials=6, compare_sim=True)
    report = deploy(cfg)
    deployed = [t["success"] for t in report["per_trial"]]
    sim = report["per_trial_sim"]
    assert sum(a != b for a, b in zip(deployed, sim, strict=True)) <= 1, (deployed, sim)
    assert report["deployment"]["faults"] == []
    # and the sim side really is igen-eval's rollout on the same seeds
    env = block_grasp_config.make_task_env()
    assert evaluate(env, scripted_policy(), "x", 6, SEED, 200, progress=False).per_trial == sim
    env.close()


def test_targets_keep_the_tasks_goal_orientation_not_a_drifted_one(sim_arm, block_grasp_config):
    """A compliant arm's hand drifts a few degrees; the policy saw its orientation held to ~0.05 degrees
    (quaternion std 0.0008 in training data), so every target asks for the training controller's goal
    orientation instead of the measured one (tolerance: 1e-9)."""
    from scipy.spatial.transform import Rotation

    goal = block_grasp_config.make_action_space().rotation
    tilted = np.array(sim_arm.env.eef_pose(), dtype=float)
    tilted[:3, :3] = Rotation.from_euler("xz", [3.0, 2.0], degrees=True).as_matrix() @ tilted[:3, :3]
    holding = SafeArm(sim_arm, sim_arm.world_from_base, SafetyLimits(), watchdog=False, goal_rotation=goal)
    drifting = SafeArm(sim_arm, sim_arm.world_from_base, SafetyLimits(), watchdog=False)
    try:
        np.testing.assert_allclose(holding.command(tilted, np.zeros(3), False, 0.05)[:3, :3], goal, atol=1e-9)
        kept = drifting.command(tilted, np.zeros(3), False, 0.05)[:3, :3]
        np.testing.assert_allclose(kept, tilted[:3, :3], atol=1e-9)
    finally:
        holding.close()
        drifting.close()
    # and igen-deploy builds its arm that way
    targets = []
    cfg = DeployConfig(robot=SimArmBackendConfig(), perception=TruthPerceptionConfig(), trials=1, max_steps=20)
    deploy(cfg, on_step=lambda rec: targets.append(rec.target[:3, :3]))
    assert len(targets) == 20
    np.testing.assert_allclose(np.stack(targets), np.broadcast_to(goal, (20, 3, 3)), atol=1e-9)


def test_the_policy_observes_the_goal_orientation_unless_told_to_observe_the_measured_one(block_grasp_config):
    """The training arm's hand tilts a few tenths of a degree while it moves; a policy can learn to read
    that tilt, which no other arm reproduces. By default the policy is told the orientation the
    controller holds; --hand_orientation=measured passes the arm's reading (tolerance 1e-6)."""
    from igen_lerobot.core.observation import robot_state

    goal = block_grasp_config.make_action_space().rotation
    goal_quat = robot_state(np.block([[goal, np.zeros((3, 1))], [np.zeros((1, 3)), np.ones((1, 1))]]), 0.08)[3:7]
    seen = {}
    for mode in ("goal", "measured"):
        rows = seen[mode] = []
        cfg = DeployConfig(
            robot=SimArmBackendConfig(),
            perception=TruthPerceptionConfig(),
            trials=1,
            max_steps=30,
            hand_orientation=mode,
        )
        report = deploy(cfg, on_step=lambda rec, rows=rows: rows.append(rec))
        assert report["hand_orientation"] == mode
    measured = np.stack([robot_state(rec.T_world_eef, 0.08)[3:7] for rec in seen["goal"]])
    assert np.abs(measured - goal_quat).max() > 1e-4  # the arm does tilt, so the choice matters
    observed = np.stack([rec.observation["observation.state"][3:7] for rec in seen["goal"]])
    np.testing.assert_allclose(observed, np.broadcast_to(goal_quat, observed.shape), atol=1e-6)
    for rec in seen["measured"]:
        np.testing.assert_allclose(
            rec.observation["observation.state"][3:7], robot_state(rec.T_world_eef, 0.08)[3:7], atol=1e-6
        )
    with pytest.raises(ConfigError, match="--hand_orientation='tilted'"):
        DeployConfig(hand_orientation="tilted")


def _checkpoint_trained_on(tmp_path: Path, name: str, meta: dict | None) -> Path:
    """A pretrained_model/ folder whose train_config.json names a dataset with ``meta`` as its igen.json."""
    root = tmp_path / f"{name}_data"
    if meta is not None:
        (root / "meta").mkdir(parents=True)
        (root / "meta" / "igen.json").write_text(json.dumps(meta))
    checkpoint = tmp_path / name / "pretrained_model"
    checkpoint.mkdir(parents=True)
    (checkpoint / "train_config.json").write_text(json.dumps({"dataset": {"repo_id": "local/x", "root": str(root)}}))
    return checkpoint


def test_auto_hand_orientation_follows_the_training_data(tmp_path):
    """A policy trained on tilt-randomised data (here a merged dataset with one such part) is told the
    measured orientation; one trained without, the goal; one whose data cannot be found, the goal,
    with a reason that names the flag to pass."""
    from lerobot_robot_igen.deploy.hand_orientation import resolve_hand_orientation

    plain = {"kind": "simulation", "robot": "panda"}
    tilted = {**plain, "randomization": {"kp_scale": [0.5, 1.5], "hand_tilt_deg": 3.0}}
    merged = {"origin": {"kind": "merge"}, "parts": [{"origin": plain}, {"origin": tilted}]}
    mode, why = resolve_hand_orientation("auto", str(_checkpoint_trained_on(tmp_path, "rand", merged)))
    assert mode == "measured" and "3 deg" in why
    mode, why = resolve_hand_orientation("auto", str(_checkpoint_trained_on(tmp_path, "plain", {"origin": plain})))
    assert mode == "goal" and "without hand tilt" in why
    mode, why = resolve_hand_orientation("auto", str(_checkpoint_trained_on(tmp_path, "gone", None)))
    assert mode == "goal" and "--hand_orientation=measured" in why
    assert resolve_hand_orientation("auto", str(tmp_path / "hub_only"))[0] == "goal"  # no train_config.json
    assert resolve_hand_orientation("auto", None)[0] == "goal"  # the scripted policy
    broken = _checkpoint_trained_on(tmp_path, "broken", {"origin": plain})
    (broken / "train_config.json").write_text("{not json")
    mode, why = resolve_hand_orientation("auto", str(broken))
    assert mode == "goal" and "not a lerobot-train config" in why
    # the loop's settings never take "auto" for "measured": unresolved, they resolve it themselves
    from lerobot_robot_igen.deploy.trials import loop_settings

    goal = np.eye(3)
    assert loop_settings(DeployConfig(hand_orientation="auto"), goal).observed_hand_rotation is goal
    assert loop_settings(DeployConfig(hand_orientation="measured"), goal).observed_hand_rotation is None
    assert resolve_hand_orientation("measured", str(_checkpoint_trained_on(tmp_path, "p2", {"origin": plain})))[0] == (
        "measured"
    )


def test_rendered_camera_and_icp_in_the_loop():
    """A simulated D415 through the real ICP estimator drives a successful grasp."""
    from lerobot_robot_igen.deploy.config_deploy import RenderedPerceptionConfig

    cfg = DeployConfig(robot=SimArmBackendConfig(), perception=RenderedPerceptionConfig(), trials=1)
    report = deploy(cfg)
    trial = report["per_trial"][0]
    assert trial["success"], trial
    assert trial["timing"]["perception"]["median_ms"] > 0


def test_a_trained_checkpoint_deploys(bc_rnn_checkpoint):
    """A lerobot-train checkpoint loads with its processors and runs the loop without a fault."""
    from igen_lerobot.training.policy_source import PolicySourceConfig

    cfg = DeployConfig(
        policy=PolicySourceConfig(path=str(bc_rnn_checkpoint)),
        robot=SimArmBackendConfig(),
        perception=TruthPerceptionConfig(),
        trials=1,
        max_steps=30,
    )
    report = deploy(cfg)
    import torch

    assert torch.get_num_threads() == 1  # one inference thread by default: no pool stalls in the 20 Hz loop
    assert report["per_trial"][0]["steps"] == 30 or report["per_trial"][0]["success"]
    assert report["policy"] == str(bc_rnn_checkpoint)


# ---------------------------------------------------------------------------------------------- faults
class DropsConnection(MujocoArm):
    """The simulated arm, losing its connection after ``n`` control periods."""

    def __init__(self, n: int) -> None:
        super().__init__()
        self.n, self.stops = n, 0

    def sync(self, period):
        self.n -= 1
        if self.n < 0:
            raise ConnectionLostError("robot at 127.0.0.1 stopped answering (test)")
        super().sync(period)

    def stop(self):
        self.stops += 1
        super().stop()


def test_connection_lost_mid_episode_stops_with_the_reason():
    arm = DropsConnection(20)
    arm.connect()
    outcome, safe = run(arm, scripted_policy())
    arm.disconnect()
    assert not outcome.success and outcome.steps == 20
    assert "stopped answering" in outcome.fault
    assert arm.stops >= 1 and safe.fault


class WildPolicy:
    """Outputs a 0.5 m step: what a checkpoint for another task or unnormalised output looks like."""

    def reset(self):
        pass

    def act(self, observation):
        return np.array([0.0, 0.5, 0.0, -1.0])


def test_out_of_bounds_action_stops_the_arm_and_refuses_more(sim_arm):
    outcome, safe = run(sim_arm, WildPolicy())
    assert outcome.steps == 0 and "refuse_delta" in outcome.fault
    with pytest.raises(Exception, match="stopped"):
        safe.command(sim_arm.env.eef_pose(), np.zeros(3), False, 0.05)


class Climber:
    def reset(self):
        pass

    def act(self, observation):
        return np.array([0.0, 0.0, 0.03, -1.0])


def test_targets_are_clamped_to_the_workspace_and_far_ones_refused(sim_arm):
    # a ceiling 2 cm above the start: the climb is clamped there, the arm never leaves the box
    low = (-0.3, -0.4, 0.805)
    limits = SafetyLimits(workspace_min=low, workspace_max=(0.3, 0.4, 1.02), clamp_margin=0.05)
    heights = []
    outcome, safe = run(sim_arm, Climber(), limits=limits, on_step=lambda r: heights.append(r.target[2, 3]))
    assert outcome.fault is None and safe.clamped_targets > 0
    assert max(heights) <= 1.02 + 1e-9
    # a box the arm already stands 10 cm outside of: refused at the first reading
    limits = SafetyLimits(workspace_min=low, workspace_max=(0.3, 0.4, 0.9), clamp_margin=0.05)
    outcome, _ = run(sim_arm, Climber(), limits=limits)
    assert outcome.steps == 0 and "outside the workspace" in outcome.fault


class FlakyCamera(SimTruthPose):
    """Loses sight of the cube after ``good`` frames (the gripper hides it, the camera dies...)."""

    def __init__(self, arm, good: int) -> None:
        super().__init__(arm)
        self.good = good

    def read(self):
        self.good -= 1
        if self.good < 0:
            raise CubeNotVisibleError("only 3 red points (need 60): cube out of view or occluded")
        return super().read()


class DivergingICP(FlakyCamera):
    """ICP fits that fail the gate after ``good`` frames."""

    def read(self):
        self.good -= 1
        if self.good < 0:
            raise PoseRejectedError("ICP fit rejected: fitness 0.41 (need >= 0.85), RMSE 7.9 mm (need <= 4.0 mm)")
        return SimTruthPose.read(self)


@pytest.mark.parametrize(("camera", "reason"), [(FlakyCamera, "out of view"), (DivergingICP, "ICP fit rejected")])
def test_stale_perception_stops_after_max_pose_age(sim_arm, camera, reason):
    settings = LoopSettings(realtime=False, max_pose_age=0.5, contact_force_threshold=0.0)
    outcome, _ = run(sim_arm, scripted_policy(), poses=camera(sim_arm, 10), settings=settings)
    # 10 good frames, then 0.5 s (10 periods at 20 Hz) on the last estimate, then a stop
    assert outcome.steps == 20 and outcome.perception_failures == 11
    assert "max_pose_age=0.5" in outcome.fault and reason in outcome.fault


def test_no_cube_at_the_start_never_moves_the_arm(sim_arm):
    outcome, _ = run(sim_arm, scripted_policy(), poses=FlakyCamera(sim_arm, 0))
    assert outcome.steps == 0 and "no estimate yet" in outcome.fault


class Interrupted:
    def __init__(self):
        self.calls = 0

    def reset(self):
        pass

    def act(self, observation):
        self.calls += 1
        if self.calls == 5:
            raise KeyboardInterrupt
        return np.array([0.0, 0.0, -0.01, -1.0])


def test_ctrl_c_stops_the_arm_then_propagates():
    arm = DropsConnection(10_000)
    arm.connect()
    with pytest.raises(KeyboardInterrupt):
        run(arm, Interrupted())
    assert arm.stops >= 1
    arm.disconnect()


class WallClockArm(DropsConnection):
    """The simulated arm on the host's clock: a hung loop is stale in wall time, as on a real arm."""

    def clock(self):
        return time.monotonic()


def test_watchdog_stops_an_arm_whose_loop_hangs():
    arm = WallClockArm(10_000)
    arm.connect()
    arm.reset_scene(SEED)
    safe = SafeArm(arm, arm.world_from_base, SafetyLimits(watchdog_timeout=0.1))
    try:
        safe.command(arm.env.eef_pose(), np.array([0.0, 0.0, -0.01]), False, 0.05)
        time.sleep(0.2)  # no command: the loop "hangs"
        deadline = time.monotonic() + 2.0
        while safe.fault is None and time.monotonic() < deadline:
            time.sleep(0.01)
        assert safe.fault is not None and "watchdog" in safe.fault
        assert arm.stops >= 1
    finally:
        safe.close()
        arm.disconnect()


def test_config_errors_name_the_field():
    from lerobot_robot_igen.arm.config_arm import ArmBackendConfig

    @ArmBackendConfig.register_subclass("test_real")
    class RealLike(ArmBackendConfig):
        def make_driver(self, env_config=None):
            raise AssertionError

    with pytest.raises(ConfigError, match="perception.type=realsense"):
        DeployConfig(robot=RealLike(), perception=TruthPerceptionConfig())
    with pytest.raises(ConfigError, match="perception.calibration"):
        RealSensePerceptionConfig(serial="123")
    with pytest.raises(ConfigError, match="compare_sim"):
        DeployConfig(robot=RealLike(), perception=RealSensePerceptionConfig(calibration="c.json"), compare_sim=True)
    with pytest.raises(ConfigError, match="trials"):
        DeployConfig(trials=0)
    with pytest.raises(ConfigError, match="--inference_threads"):
        DeployConfig(inference_threads=0)


def test_camera_not_found_and_missing_calibration_are_clear(tmp_path):
    from lerobot_robot_igen.cameras.realsense import CameraError
    from lerobot_robot_igen.deploy.trials import make_pose_source
    from lerobot_robot_igen.perception.camera_model import save_extrinsics

    missing = DeployConfig(perception=RealSensePerceptionConfig(calibration=str(tmp_path / "none.json")))
    with pytest.raises(ConfigError, match="none.json"):
        make_pose_source(missing, None)
    save_extrinsics(tmp_path / "calib.json", np.eye(4))
    absent = DeployConfig(
        perception=RealSensePerceptionConfig(serial="000000000000", calibration=str(tmp_path / "calib.json"))
    )
    with pytest.raises(CameraError, match="000000000000"):
        make_pose_source(absent, None)


def test_trial_seeds_are_igen_evals(sim_arm, block_grasp_config):
    env = block_grasp_config.make_task_env()
    for i in range(3):
        env.reset(episode_seed(SEED, i))
        sim_arm.reset_scene(episode_seed(SEED, i))
        np.testing.assert_array_equal(env.corruption, sim_arm.env.corruption)
        np.testing.assert_allclose(env.true_object_poses()["cube"], sim_arm.env.true_object_poses()["cube"], atol=1e-12)
    env.close()


def rrd_rows(path) -> dict[str, int]:
    """Rows logged per entity in a Rerun recording, read back with Rerun's own reader."""
    from rerun.experimental import RrdReader

    rows: dict[str, int] = {}
    for chunk in RrdReader(path).stream():
        rows[chunk.entity_path] = rows.get(chunk.entity_path, 0) + chunk.num_rows
    return rows


def test_deployment_logs_to_rerun(tmp_path):
    """Camera images, the segmented cloud, ICP change, commanded vs measured hand, every period."""
    from igen_lerobot.viz.rerun_log import RerunConfig
    from lerobot_robot_igen.deploy.config_deploy import RenderedPerceptionConfig

    out = tmp_path / "deploy.rrd"
    cfg = DeployConfig(
        robot=SimArmBackendConfig(),
        perception=RenderedPerceptionConfig(),
        trials=1,
        max_steps=12,
        rerun=RerunConfig(mode="save", path=str(out)),
    )
    deploy(cfg)
    rows = rrd_rows(out)
    for entity in ("eef/measured", "eef/commanded", "cube/believed", "cube/perceived", "camera/color", "camera/depth"):
        assert rows.get(f"/deploy/{entity}") == 12, (entity, rows.get(f"/deploy/{entity}"))
    assert rows.get("/deploy/cube/cloud") == 12 and rows.get("/deploy/cube/icp_change_mm") == 11


def test_a_missing_camera_leaves_no_arm_running(tmp_path):
    import threading

    from lerobot_robot_igen.cameras.realsense import CameraError
    from lerobot_robot_igen.perception.camera_model import save_extrinsics

    save_extrinsics(tmp_path / "calib.json", np.eye(4))
    perception = RealSensePerceptionConfig(serial="000000000000", calibration=str(tmp_path / "calib.json"))
    with pytest.raises(CameraError, match="000000000000"):
        deploy(DeployConfig(robot=SimArmBackendConfig(), perception=perception, trials=1))
    assert not any(t.name == "arm-watchdog" and t.is_alive() for t in threading.enumerate())


class JumpingCamera(SimTruthPose):
    """The true pose, except every ``every``-th frame slid by one cube edge (a fit that slid by a face)."""

    def __init__(self, arm, every: int = 5) -> None:
        super().__init__(arm)
        self.every, self.count = every, 0

    def read(self):
        reading = super().read()
        self.count += 1
        if self.count % self.every == 0:
            reading.T_base_cube = reading.T_base_cube.copy()
            reading.T_base_cube[0, 3] += 0.05
        return reading


def test_a_jump_the_cube_could_not_make_is_rejected_bridged_and_recorded(sim_arm):
    records = []
    settings = LoopSettings(realtime=False, contact_force_threshold=0.0)
    camera = JumpingCamera(sim_arm)
    outcome, _ = run(sim_arm, scripted_policy(), poses=camera, settings=settings, on_step=records.append)
    truth, _ = run(sim_arm, scripted_policy(), settings=settings)
    assert outcome.success and outcome.steps == truth.steps  # the slid frames never reached the policy
    jumps = [r for r in records if r.pose_rejection is not None]
    assert len(jumps) == outcome.rejected_jumps == len(outcome.pose_rejections) == outcome.steps // 5
    assert all(not r.pose_fresh and r.pose_rejection.startswith("jump: the estimate jumped 50 mm") for r in jumps)
    assert outcome.pose_rejections[0] == {"step": 4, "kind": "jump", "reason": jumps[0].pose_rejection[len("jump: ") :]}
    assert outcome.to_json()["rejected_jumps"] == outcome.rejected_jumps


class DoubtfulCamera(SimTruthPose):
    """The true pose, rated 0.5 by its estimator (a fit that leaves half its evidence unexplained)."""

    def read(self):
        from lerobot_robot_igen.perception.cube_pose import CubePoseEstimate

        reading = super().read()
        reading.estimate = CubePoseEstimate(reading.T_base_cube, fitness=0.5, rmse=0.002, num_points=300, seconds=0.0)
        return reading


def test_low_confidence_estimates_are_not_acted_on(sim_arm):
    settings = LoopSettings(realtime=False, contact_force_threshold=0.0, max_pose_age=0.2)  # min_confidence 0.8
    outcome, _ = run(sim_arm, scripted_policy(), poses=DoubtfulCamera(sim_arm), settings=settings)
    # the first estimate is not trusted and there is nothing to bridge with: the arm never moves
    assert outcome.steps == 0 and outcome.low_confidence == 1
    assert "confidence 0.50 < min_confidence 0.8" in outcome.fault and "no estimate yet" in outcome.fault


def test_pose_gate_settings_name_the_field():
    from lerobot_robot_igen.perception.pose_gate import PoseGateSettings

    with pytest.raises(ConfigError, match="pose_gate.max_cube_speed"):
        PoseGateSettings(max_cube_speed=0.0)
    with pytest.raises(ConfigError, match="pose_gate.min_confidence"):
        PoseGateSettings(min_confidence=1.5)


def test_rejected_estimates_reach_rerun_and_the_report(tmp_path, monkeypatch):
    from igen_lerobot.viz.rerun_log import RerunConfig
    from lerobot_robot_igen.deploy import trials as deploy_module

    monkeypatch.setattr(deploy_module, "make_pose_source", lambda cfg, driver: JumpingCamera(driver, every=3))
    out = tmp_path / "deploy.rrd"
    cfg = DeployConfig(
        robot=SimArmBackendConfig(),
        perception=TruthPerceptionConfig(),
        trials=1,
        max_steps=12,
        rerun=RerunConfig(mode="save", path=str(out)),
    )
    report = deploy(cfg)
    trial = report["per_trial"][0]
    assert trial["rejected_jumps"] == 4 and [r["step"] for r in trial["pose_rejections"]] == [2, 5, 8, 11]
    rows = rrd_rows(out)
    assert rows.get("/deploy/perception/rejections") == 4 and rows.get("/deploy/cube/estimate_used") == 12


class FailsSecondReset(MujocoArm):
    """The simulated arm that cannot be set up for its second trial (as a real arm failing to go home)."""

    def reset_scene(self, seed):
        if seed == episode_seed(SEED, 1):
            raise DriverError("the robot refused the move home: RuntimeError: Motion planner failed (test)")
        super().reset_scene(seed)


def test_a_run_that_cannot_start_its_next_trial_keeps_the_trials_it_ran(tmp_path, capsys):
    """The JSON report holds trial 1 and says why the run stopped before trial 2; the command exits non-zero."""
    from lerobot_robot_igen.deploy.igen_deploy import deploy_main

    @ArmBackendConfig.register_subclass("test_fails_second_reset")
    class FailsSecondResetConfig(SimArmBackendConfig):
        def make_driver(self, env_config=None):
            return FailsSecondReset(env_config=env_config)

    output = tmp_path / "report.json"
    cfg = DeployConfig(
        robot=FailsSecondResetConfig(),
        perception=TruthPerceptionConfig(),
        trials=3,
        compare_sim=True,
        output=str(output),
    )
    with pytest.raises(SystemExit) as exit_info:
        deploy_main(cfg)
    assert exit_info.value.code == 1
    report = json.loads(output.read_text())
    assert report["stopped"]["before_trial"] == 1 and "Motion planner failed" in report["stopped"]["reason"]
    assert len(report["per_trial"]) == 1 and report["deployment"]["trials"] == 1
    assert len(report["per_trial_sim"]) == 1  # igen-eval's side covers the same trials
    assert "run stopped before trial 2 of 3" in capsys.readouterr().out


def test_nut_insertion_rehearses_on_the_mujoco_arm_with_7d_actions():
    """Nut Insertion deployed as I-Gen would deploy it: its own spec and 6-DOF action space, not Block Grasp's.

    The MuJoCo arm hosts the task's scene (the nut starts in the closed hand) and the scripted
    policy's 7-D actions turn the hand. Truth perception is the requirement: the cameras' estimator
    perceives Block Grasp's cube only, and no perception of the nut or peg exists, so another task
    rehearses with ``--perception.type=truth`` (a camera config is refused with that advice).
    """
    records = []
    cfg = DeployConfig(
        task="nut_insertion",
        robot=SimArmBackendConfig(),
        perception=TruthPerceptionConfig(),
        trials=2,
        compare_sim=True,
    )
    report = deploy(cfg, on_step=records.append)
    assert report["deployment"]["trials"] == 2 and len(report["per_trial"]) == 2
    assert report["deployment"]["faults"] == []
    assert {r.action.shape for r in records} == {(7,)}
    assert any(np.linalg.norm(r.action[3:6]) > 0 for r in records)  # the hand is turned, not only moved
    assert records[0].state.gripper_width < 0.036  # the nut starts held
    assert [t["success"] for t in report["per_trial"]] == report["per_trial_sim"]
    assert all(t["revealed_at"] is not None for t in report["per_trial"])  # the nut-peg contact was felt
    with pytest.raises(ConfigError, match="perception.type=truth"):
        deploy(DeployConfig(task="nut_insertion", robot=SimArmBackendConfig(), trials=1))


@pytest.mark.parametrize("task", ["nut_insertion", "coffee"])
def test_the_simulated_arm_homes_where_its_tasks_episodes_start(task):
    """move_home goes to the task's own start pose (position and orientation), not Block Grasp's.

    Tolerance: 5 mm, move_home's own settling bound; orientation within 2 degrees.
    """
    from igen_lerobot.core.env_config import task_config_class

    arm = MujocoArm(env_config=task_config_class(task)())
    arm.connect()
    try:
        start = arm.read_state().T_base_eef
        block_grasp = MujocoArm()
        block_grasp.connect()
        block_grasp_home = block_grasp.read_state().T_base_eef[:3, 3]
        block_grasp.disconnect()
        assert np.linalg.norm(start[:3, 3] - block_grasp_home) > 0.01  # the homes differ: the test can tell them apart
        away = start.copy()
        away[:3, 3] += (0.04, -0.03, 0.03)
        arm.send_target(away)
        for _ in range(30):
            arm.sync(1.0 / arm.config.fps)
        assert np.linalg.norm(arm.read_state().T_base_eef[:3, 3] - start[:3, 3]) > 0.02
        arm.move_home()
        home = arm.read_state()
        assert np.linalg.norm(home.T_base_eef[:3, 3] - start[:3, 3]) < 0.005
        cos = (np.trace(home.T_base_eef[:3, :3].T @ start[:3, :3]) - 1) / 2
        assert np.degrees(np.arccos(np.clip(cos, -1, 1))) < 2.0
    finally:
        arm.disconnect()
