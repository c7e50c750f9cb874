"""Simulation speed of each task on one core: control steps/s vs the raw physics limit, reset time.

Run:  MUJOCO_GL=egl .venv/bin/python benchmarks/bench_env.py [--tasks block_grasp nut_insertion] \
          [--steps 3000] [--repeats 3] [--robosuite] [--clock cpu]

The physics limit is measured twice: from the state after a reset (the arm at rest) and from
every state the timed loop visited (its contacts included), which is what the loop itself pays.
Pinned to CPU 0 with single-threaded BLAS, so the number is per core; each figure is the median
of ``--repeats`` runs, the tasks interleaved within a repeat (this VM's speed drifts by +-20%
between runs). ``--robosuite`` also times robosuite's stock Lift task with its Panda OSC
controller for comparison. ``--clock cpu`` times with the process's CPU time instead of the wall
clock: the per-core rate on a machine shared with other work (the default, ``wall``, needs an idle one).
"""

import argparse
import json
import os
import platform
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")

import mujoco  # noqa: E402
import numpy as np  # noqa: E402

_clock = time.perf_counter  # --clock cpu: time.process_time


def time_env(task: str, steps: int) -> dict:
    import dataclasses

    from igen_lerobot.collection.record import record_demo
    from igen_lerobot.core.env_config import task_config_class
    from igen_lerobot.core.error_models import NoNoise

    cfg = task_config_class(task)()
    t0 = _clock()
    env = cfg.make_task_env()
    build_s = _clock() - t0
    env.reset(0)
    env.step(np.zeros(len(env.spec.action_names)))  # compile the numba kernels outside the timed loops

    resets = []
    for seed in range(50):
        t0 = _clock()
        env.reset(seed)
        resets.append(_clock() - t0)

    # env.step + observe, driven by the scripted base policy (what generation runs); the resets
    # between its episodes are timed apart: a reset is not a control step, and an in-hand task's
    # reset runs settling periods of its own (its cost is the reset row above)
    policy = cfg.make_scripted_policy()
    done, seed, episodes, policy_s, loop_reset_s = 0, 0, 0, 0.0, 0.0
    t0 = _clock()
    while done < steps:
        t_reset = _clock()
        obs = env.reset(seed)
        loop_reset_s += _clock() - t_reset
        episodes += 1
        for _ in range(cfg.episode_length):
            t_act = _clock()
            action = policy.act(obs)
            policy_s += _clock() - t_act  # the agent's share, apart from the simulator's
            info = env.step(action)
            obs = env.observe()
            done += 1
            if info.success or done >= steps:
                break
        seed += 1
    loop_s = _clock() - t0

    # raw physics of the same model and state: 25 substeps per control step, no controller
    model, data = env.model, env.data
    env.reset(0)
    n_raw = steps * env.arm.substeps // 5
    t0 = _clock()
    for _ in range(n_raw):
        mujoco.mj_step(model, data)
    raw_s = _clock() - t0
    raw_ctrl_rate = n_raw / raw_s / env.arm.substeps

    # the same physics from the very states the timed loop visited (contacts included: a task whose
    # insertion touches a lot costs more per substep than the arm at rest above measures)
    states_limit = same_states_physics_limit(env, cfg, policy, steps)

    # scripted operator success on uncorrupted episodes
    clean = dataclasses.replace(cfg, corruption=NoNoise()).make_task_env()
    operator = cfg.make_scripted_operator()
    ok = sum(record_demo(clean, operator, 10_000 + s, cfg.episode_length).success for s in range(50))
    step_rate = steps / (loop_s - loop_reset_s)
    return {
        "env_build_s": build_s,
        "reset_ms_median": 1000 * float(np.median(resets)),
        "control_steps_per_s": step_rate,
        "mj_step_per_s": n_raw / raw_s,
        "physics_limit_control_steps_per_s": raw_ctrl_rate,
        "ratio_to_physics_limit": step_rate / raw_ctrl_rate,
        "physics_limit_same_states_control_steps_per_s": states_limit,
        "ratio_to_physics_limit_same_states": step_rate / states_limit,
        "scripted_policy_ms_per_step": 1000 * policy_s / steps,
        "ratio_to_physics_limit_without_policy": (steps / (loop_s - loop_reset_s - policy_s)) / raw_ctrl_rate,
        "episode_steps_mean": steps / episodes,
        "loop_share_in_resets": loop_reset_s / loop_s,
        "control_steps_per_s_with_resets": steps / loop_s,
        "ratio_to_physics_limit_with_resets": (steps / loop_s) / raw_ctrl_rate,
        "substeps": env.arm.substeps,
        "scripted_operator_success_50_seeds": ok / 50,
    }


def same_states_physics_limit(env, cfg, policy, steps: int) -> float:
    """Control steps/s of physics alone, each timed from a state the control loop visited.

    The loop's episodes are run again (untimed) saving MuJoCo's integration state before every
    control step; then each state is restored and its substeps stepped with the controls it held.
    """
    model, data = env.model, env.data
    kind = mujoco.mjtState.mjSTATE_INTEGRATION
    size = mujoco.mj_stateSize(model, kind)
    states, done, seed = [], 0, 0
    while done < steps:
        obs = env.reset(seed)
        for _ in range(cfg.episode_length):
            state = np.empty(size)
            mujoco.mj_getState(model, data, state, kind)
            states.append(state)
            info = env.step(policy.act(obs))
            obs = env.observe()
            done += 1
            if info.success or done >= steps:
                break
        seed += 1
    physics_s = 0.0
    for state in states:
        mujoco.mj_setState(model, data, state, kind)
        t0 = _clock()
        for _ in range(env.arm.substeps):
            mujoco.mj_step(model, data)
        physics_s += _clock() - t0
    return len(states) / physics_s


def time_robosuite_lift(steps: int) -> dict:
    import robosuite as suite
    from robosuite.controllers import load_composite_controller_config

    env = suite.make(
        "Lift",
        robots="Panda",
        controller_configs=load_composite_controller_config(controller="BASIC"),
        has_renderer=False,
        has_offscreen_renderer=False,
        use_camera_obs=False,
        control_freq=20,
        horizon=100_000,
    )
    env.reset()
    action = np.zeros(env.action_dim)
    for _ in range(50):  # numba warm-up
        env.step(action)
    t0 = _clock()
    for _ in range(steps):
        env.step(action)
    return {"robosuite_lift_control_steps_per_s": steps / (_clock() - t0)}


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--tasks", nargs="+", default=["block_grasp", "nut_insertion"])
    parser.add_argument("--steps", type=int, default=3000)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--robosuite", action="store_true")
    parser.add_argument("--clock", choices=("wall", "cpu"), default="wall")
    args = parser.parse_args()
    global _clock
    _clock = time.process_time if args.clock == "cpu" else time.perf_counter
    os.sched_setaffinity(0, {0})
    runs = [{task: time_env(task, args.steps) for task in args.tasks} for _ in range(args.repeats)]
    result = {
        "machine": f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores",
        "repeats": args.repeats,
        "clock": args.clock,
    }
    for task in args.tasks:
        result[task] = {key: float(np.median([r[task][key] for r in runs])) for key in runs[0][task]}
    if args.robosuite:
        lift = [time_robosuite_lift(min(args.steps, 600)) for _ in range(args.repeats)]
        result["robosuite_lift"] = {k: float(np.median([r[k] for r in lift])) for k in lift[0]}
    print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
