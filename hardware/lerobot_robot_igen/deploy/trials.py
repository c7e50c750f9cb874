"""Trials of a policy on an arm: build the parts from a :class:`DeployConfig`, run, summarise.

A rehearsal runs trial ``i`` on igen-eval's scene ``i`` with the same pose error, so
``--compare_sim=true`` can report the deployment path's success next to the policy's own sim
success on identical situations. Two rehearsals exist: the MuJoCo arm (``--robot.type=sim``, the
training simulator itself) and the franky backend against franky-sim (``--robot.type=franky
--perception.type=franky_sim``: a different simulator behind the real driver stack, whose cube is
placed per trial through its scene channel).
"""

from __future__ import annotations

import logging
import time

import numpy as np
from tqdm import tqdm

from igen_lerobot.core.actions import DeltaPositionActions
from igen_lerobot.core.env_config import task_config_class
from igen_lerobot.core.seeding import episode_seed
from igen_lerobot.evaluation.trials import evaluate, wilson_interval
from igen_lerobot.training.policy_source import make_base_policy
from igen_lerobot.viz.rerun_log import EpisodeLogger
from lerobot_robot_igen.arm.driver import ArmDriver, ArmState, DriverError
from lerobot_robot_igen.arm.safe_arm import SafeArm
from lerobot_robot_igen.deploy.actions import ActionLayout
from lerobot_robot_igen.deploy.belief import check_deployable, cube_belief
from lerobot_robot_igen.deploy.config_deploy import (
    DeployConfig,
    FrankySimPerceptionConfig,
    RealSensePerceptionConfig,
    RenderedPerceptionConfig,
    TruthPerceptionConfig,
)
from lerobot_robot_igen.deploy.hand_orientation import resolve_hand_orientation
from lerobot_robot_igen.deploy.loop import EpisodeOutcome, LoopSettings, StepRecord, run_episode, timing_stats
from lerobot_robot_igen.perception.pose_source import PoseSource

logger = logging.getLogger(__name__)


def holds_cube(gripper_width: float, cube_size: float) -> bool:
    """The fingers stopped on something cube-sized (not closed on air, not wide open)."""
    return 0.6 * cube_size <= gripper_width <= 1.1 * cube_size


class GraspLiftJudge:
    """Success on a real arm: the gripper closed on something cube-sized and lifted it 4 cm.

    (A rehearsal uses the simulator's own success test instead.)
    """

    def __init__(self, cube_size: float = 0.05, lift: float = 0.04, layout: ActionLayout | None = None) -> None:
        """``layout``: where the action keeps the gripper (default: Block Grasp's actions)."""
        self.cube_size, self.lift = cube_size, lift
        self.layout = layout or ActionLayout.of(task_config_class("block_grasp")().task_spec.action_names)
        self._grasp_z: float | None = None

    def __call__(self, state: ArmState, action: np.ndarray) -> bool:
        closed = self.layout.gripper_closed(action)
        holding = closed and holds_cube(state.gripper_width, self.cube_size)
        if not holding:
            self._grasp_z = None
            return False
        z = float(state.T_base_eef[2, 3])
        if self._grasp_z is None:
            self._grasp_z = z
        return z - self._grasp_z >= self.lift


def make_pose_source(cfg: DeployConfig, driver: ArmDriver) -> PoseSource:
    """The configured cube pose source (sim sources need the simulated arm)."""
    from lerobot_robot_igen.perception import pose_source

    p = cfg.perception
    if isinstance(p, TruthPerceptionConfig):
        return pose_source.SimTruthPose(driver)
    if isinstance(p, FrankySimPerceptionConfig):
        return pose_source.FrankySimCubePose(cfg.robot.host, p.port)
    if isinstance(p, RenderedPerceptionConfig):
        return pose_source.RenderedICPPose(driver, p.distance, p.azimuth_deg, p.elevation_deg, p.noise)
    if isinstance(p, RealSensePerceptionConfig):
        from lerobot_robot_igen.cameras.realsense import RealSenseConfig, RealSenseRGBD
        from lerobot_robot_igen.perception.camera_model import load_extrinsics

        T_base_camera = load_extrinsics(p.calibration)
        camera = RealSenseRGBD(RealSenseConfig(serial=p.serial, recording=p.recording))
        return pose_source.RealSenseICPPose(camera, T_base_camera)
    raise TypeError(f"unknown perception config {type(p).__name__}")


def _summary(name: str, outcomes: list[EpisodeOutcome]) -> dict:
    successes = sum(o.success for o in outcomes)
    merged: dict[str, list[float]] = {}
    for o in outcomes:
        for key, stats in o.timing.items():
            if stats:
                merged.setdefault(key, []).append(stats["max_ms"])
    return {
        "name": name,
        "trials": len(outcomes),
        "successes": successes,
        "success_rate": successes / len(outcomes),
        "ci95": wilson_interval(successes, len(outcomes)),
        "faults": [o.fault for o in outcomes if o.fault],
        "worst_ms": {k: max(v) for k, v in merged.items()},
    }


def loop_settings(
    cfg: DeployConfig, goal_rotation: np.ndarray | None, driver=None, hand_orientation: str | None = None
) -> LoopSettings:
    """The loop's settings from the command line; ``goal_rotation`` is the task's (task frame; None: 6-DOF).

    ``driver``: the connected arm, whose own clock paces the loop with ``--pace_on=arm`` where it has one.
    ``hand_orientation``: ``goal`` or ``measured``, as ``--hand_orientation`` resolved (None: resolved here,
    so that ``auto`` never reaches the loop unresolved).
    """
    if hand_orientation is None:
        hand_orientation, _ = resolve_hand_orientation(cfg.hand_orientation, cfg.policy.path)
    own_clock = driver is not None and cfg.pace_on == "arm" and driver.robot_time() is not None
    return LoopSettings(
        pace_clock=driver.robot_time if own_clock else None,
        fps=cfg.fps,
        max_steps=cfg.max_steps,
        contact_force_threshold=cfg.contact_force_threshold,
        max_pose_age=cfg.max_pose_age,
        realtime=bool(cfg.realtime),
        pose_gate=cfg.pose_gate,
        observed_hand_rotation=goal_rotation if hand_orientation == "goal" else None,  # None: measured
    )


def deploy(cfg: DeployConfig, on_step=None) -> dict:
    """Run ``cfg.trials`` episodes; returns (and optionally writes) a JSON-able report."""
    env_cfg = task_config_class(cfg.task)()  # the task from LeRobot's env registry, as igen-eval finds it
    check_deployable(env_cfg.task_spec, truth=isinstance(cfg.perception, TruthPerceptionConfig))
    import torch

    torch.set_num_threads(cfg.inference_threads)
    policy = make_base_policy(cfg.policy, env_cfg)
    hand_orientation, hand_orientation_reason = resolve_hand_orientation(cfg.hand_orientation, cfg.policy.path)
    logger.info("the policy is told the %s hand orientation (%s)", hand_orientation, hand_orientation_reason)
    # the task's MuJoCo scene is needed before the arm: igen-eval's rollouts for --compare_sim, and the
    # situations a franky-sim rehearsal recreates (done first, so no arm idles connected meanwhile)
    sim_result = None
    if cfg.compare_sim:
        env = env_cfg.make_task_env()
        try:
            sim_result = evaluate(env, policy, "sim", cfg.trials, cfg.seed, cfg.max_steps)
        finally:
            env.close()
    situations = _trial_situations(env_cfg, cfg) if isinstance(cfg.perception, FrankySimPerceptionConfig) else None
    driver = cfg.robot.make_driver(env_cfg)
    driver.connect()
    simulated = cfg.robot.simulated
    world_from_base = driver.world_from_base if driver.world_from_base is not None else cfg.real_world_from_base()
    # targets keep the task's goal orientation, as its training controller's goal did: the policy saw
    # that orientation held within a fraction of a degree, and reads a drifted one as a new situation.
    # A 6-DOF task has none: its actions turn the hand
    action_space = env_cfg.make_action_space()
    goal_rotation = action_space.rotation if isinstance(action_space, DeltaPositionActions) else None
    arm = SafeArm(driver, world_from_base, cfg.safety, goal_rotation=goal_rotation)
    try:
        poses = make_pose_source(cfg, driver)
    except BaseException:  # no camera: leave the arm stopped and the connection closed
        arm.close()
        driver.disconnect()
        raise
    settings = loop_settings(cfg, goal_rotation, driver, hand_orientation)
    outcomes: list[EpisodeOutcome] = []
    step_times: list[float] = []
    period_times: list[float] = []

    viz = EpisodeLogger.open(cfg.rerun, env_cfg.task_spec, "deploy")
    viz_step = deploy_logger(viz, arm) if viz is not None else None

    def record(rec: StepRecord) -> None:
        if viz_step is not None:
            viz_step(rec)
        step_times.append(rec.seconds.get("step", 0.0))
        if "period" in rec.seconds:
            period_times.append(rec.seconds["period"])
        if on_step is not None:
            on_step(rec)

    started = time.perf_counter()
    stopped: dict | None = None  # the run ended before its last trial: which one, and why
    try:
        with tqdm(total=cfg.trials, desc=f"deploy {cfg.policy.describe()}", unit="trial") as bar:
            for i in range(cfg.trials):
                seed = episode_seed(cfg.seed, i)
                try:
                    offset, judge = _start_trial(cfg, driver, poses, situations, world_from_base, i, seed)
                except DriverError as err:
                    # the arm cannot be set up for the next trial (it failed to go home): stop here,
                    # and keep the trials already run in the report
                    if not outcomes:
                        raise
                    logger.error("run stopped before trial %d: %s", i + 1, err)
                    stopped = {"before_trial": i, "reason": str(err)}
                    break
                belief = cube_belief(offset, cfg.reveal)
                outcome = run_episode(arm, poses, policy, belief, settings, judge, record, env_cfg, seed)
                outcomes.append(outcome)
                if not simulated:
                    driver.set_gripper(False)
                bar.update()
                bar.set_postfix(success=f"{sum(o.success for o in outcomes)}/{len(outcomes)}")
    finally:
        arm.close()
        poses.close()
        driver.disconnect()
        if viz is not None:
            viz.close()
    report = {
        "stopped": stopped,
        "policy": cfg.policy.describe(),
        "robot": cfg.robot.get_choice_name(type(cfg.robot)),
        "perception": cfg.perception.get_choice_name(type(cfg.perception)),
        "hand_orientation": hand_orientation,
        "hand_orientation_reason": hand_orientation_reason,
        "seed": cfg.seed,
        "trial_seeds": [episode_seed(cfg.seed, i) for i in range(len(outcomes))],  # igen-eval's, in a rehearsal
        "deployment": _summary("deployment", outcomes),
        "per_trial": [o.to_json() for o in outcomes],
        "loop": {"step": timing_stats(step_times), "period": timing_stats(period_times)},
        "pace": _pace_summary(settings, outcomes),
        "seconds": time.perf_counter() - started,
    }
    if sim_result is not None:
        same_trials = sim_result.per_trial[: len(outcomes)]  # the trials the deployment ran
        successes = sum(same_trials)
        report["sim"] = {
            "success_rate": successes / len(same_trials),
            "ci95": wilson_interval(successes, len(same_trials)),
            "successes": successes,
        }
        report["per_trial_sim"] = same_trials
    return report


def _pace_summary(settings: LoopSettings, outcomes: list[EpisodeOutcome]) -> dict:
    """Which clock the periods were measured on, and how fast it ran against the wall clock (median over trials)."""
    if not settings.realtime:
        return {"clock": "none (as fast as the simulated arm steps)"}
    if settings.pace_clock is None:
        return {"clock": "wall"}
    rates = [o.pace_clock_rate for o in outcomes if o.pace_clock_rate is not None]
    return {"clock": "arm", "arm_seconds_per_wall_second": float(np.median(rates)) if rates else None}


def _start_trial(cfg: DeployConfig, driver, poses, situations, world_from_base, i: int, seed: int):
    """Set up trial ``i`` (scene or arm home, cube); its pose error and success judge."""
    if cfg.robot.simulated:
        driver.reset_scene(seed)
        return driver.env.corruption, _sim_judge(driver)  # igen-eval's trial i: same scene, same pose error
    if situations is not None:
        return _franky_sim_trial(driver, poses.scene, situations[i], world_from_base)
    if cfg.prompt:
        input(f"trial {i + 1}/{cfg.trials}: place the cube, clear the workspace, press Enter ")
    driver.move_home()
    return cfg.corruption.sample(np.random.default_rng(seed)), GraspLiftJudge()


def deploy_logger(viz: EpisodeLogger, arm: SafeArm):
    """The Rerun hook of the loop: each period's poses, camera frames, cloud and ICP change (task frame)."""
    state = {"step": 0, "previous": None}

    def log(rec: StepRecord) -> None:
        reading = rec.reading
        perceived = rec.T_world_cube[:3, 3] if rec.pose_fresh else None
        cloud = None
        if reading is not None and reading.estimate is not None and reading.estimate.points is not None:
            points = reading.estimate.points
            cloud = points @ arm.T_world_base[:3, :3].T + arm.T_world_base[:3, 3]
        viz.log_deploy_step(
            state["step"],
            measured_eef=rec.T_world_eef[:3, 3],
            commanded_eef=rec.target[:3, 3],
            believed_cube=rec.believed_position,
            perceived_cube=perceived,
            previous_cube=state["previous"],
            color=None if reading is None else reading.color,
            depth=None if reading is None else reading.depth,
            cloud=cloud,
            contact=rec.contact,
            timing_ms={k: 1000 * v for k, v in rec.seconds.items()},
            pose_rejection=rec.pose_rejection,
        )
        if perceived is not None:
            state["previous"] = perceived
        state["step"] += 1

    return log


def _trial_situations(env_cfg, cfg: DeployConfig) -> list[tuple[np.ndarray, np.ndarray]]:
    """``(T_world_cube, pose error)`` of igen-eval's trials 0..trials-1 (what a franky-sim rehearsal recreates)."""
    env = env_cfg.make_task_env()
    try:
        situations = []
        for i in range(cfg.trials):
            env.reset(episode_seed(cfg.seed, i))
            situations.append((env.true_object_poses()["cube"].copy(), np.asarray(env.corruption, float).copy()))
        return situations
    finally:
        env.close()


def _franky_sim_trial(driver, scene, situation, world_from_base: np.ndarray):
    """One igen-eval trial on franky-sim: the arm home, the cube where the trial has it; its pose error and judge."""
    from lerobot_env_igen.block_grasp.spec import CUBE_HALF
    from lerobot_robot_igen.arm.franky_sim_scene import LIFT_SUCCESS

    T_world_cube, corruption = situation
    driver.move_home()
    T_base_cube = np.linalg.inv(world_from_base) @ T_world_cube
    scene.place_cube(T_base_cube[0, 3], T_base_cube[1, 3], float(np.arctan2(T_base_cube[1, 0], T_base_cube[0, 0])))
    cube = 2 * CUBE_HALF

    def judge(state: ArmState, action: np.ndarray) -> bool:
        return holds_cube(state.gripper_width, cube) and scene.lifted() >= LIFT_SUCCESS

    return corruption, judge


def _sim_judge(driver):
    return lambda state, action: driver.task_success()
