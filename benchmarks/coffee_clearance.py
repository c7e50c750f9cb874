"""Coffee: at what offset from the holder's axis the pod goes in, and where it stays on the rim or the body.

Two measurements on the task's own scene (MuJoCo, the composite machine and the tapered pod):

* ``drop``: the pod alone, upright, released at rest with its bottom 1 cm above the rim, its axis
  off the holder's by ``d`` along -x (away from the machine's body); the arm waits away above.
  After 2 s: the pod bottom's height above the holder's floor, its tilt, and ``seated()``.
* ``insert``: the pod in the hand, the scripted base policy believing the machine ``d`` off (no
  other error) and never told better (``--env.reveal=none``): it goes straight down and lets go
  once the pod is at the floor. After its 200 steps: success, the first pod-machine contact (step,
  height above the rim, the machine geom), and where the pod is. Directions: -x (away from the
  body), +y (along its front) and +x (towards the body).

Run:  MUJOCO_GL=egl .venv/bin/python benchmarks/coffee_clearance.py [--offsets 0 2 3 4 5 6 8 10 20 30 40]
"""

import argparse
import dataclasses

import mujoco
import numpy as np

from igen_lerobot.core.belief import Reveal
from igen_lerobot.core.error_models import BoxNoise
from lerobot_env_igen.coffee.config import CoffeeEnvConfig
from lerobot_env_igen.coffee.spec import FLOOR_Z, POD_HALF_HEIGHT, RING_TOP_Z
from lerobot_env_igen.panda import TOP_DOWN_ROT

DIRECTIONS = {"-x": np.array([-1.0, 0.0]), "+y": np.array([0.0, 1.0]), "+x": np.array([1.0, 0.0])}


def _state(env) -> tuple[float, float]:
    pod = env.true_object_poses()["pod"]
    tilt = float(np.degrees(np.arccos(np.clip(pod[2, 2], -1.0, 1.0))))
    return float(pod[2, 3] - POD_HALF_HEIGHT - FLOOR_Z), tilt


def drop(env, offset_xy: np.ndarray) -> str:
    env.reset(0)
    env.arm.reset()  # fingers open, nothing in the hand
    holder = env.true_object_poses()["machine"][:3, 3]
    env.set_free_pose("pod", np.array([*(holder[:2] + offset_xy), RING_TOP_Z + 0.01 + POD_HALF_HEIGHT]))
    home = env.arm.eef_pos() + np.array([0.0, 0.0, 0.05])
    for _ in range(40):
        env.arm.control_period(home, False, TOP_DOWN_ROT)
    height, tilt = _state(env)
    return f"{'seated' if env.seated() else 'out'} {1000 * height:.1f} mm {tilt:.0f} deg"


def insert(cfg, offset_xy: np.ndarray) -> str:
    env, policy = cfg.make_task_env(), cfg.make_scripted_policy()
    obs = env.reset(0, corruption=np.array([*offset_xy, 0.0]))  # believed = true + offset: it lands there
    first, success = "", False
    for t in range(cfg.episode_length):
        info = env.step(policy.act(obs))
        obs = env.observe()
        if info.revealed and not first:
            contact = env.last_reveal_contact
            geoms = {mujoco.mj_id2name(env.model, mujoco.mjtObj.mjOBJ_GEOM, int(g)) for g in contact.geom_pairs[0]}
            part = next(g for g in geoms if g.startswith("machine")).removeprefix("machine_")
            first = f"touch {part} at {t} ({1000 * (contact.position[2] - RING_TOP_Z):+.0f} mm), "
        if info.success:
            success = True
            break
    height, tilt = _state(env)
    env.close()
    return f"{first}{'success' if success else 'fail'} {1000 * height:.1f} mm {tilt:.0f} deg"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--offsets", type=float, nargs="+", default=[0, 2, 3, 4, 5, 6, 8, 10, 20, 30, 40])
    args = parser.parse_args()
    cfg = dataclasses.replace(
        CoffeeEnvConfig(), corruption=BoxNoise(half_extent=(0.05, 0.05, 0.05), min_abs=(0.0, 0.0, 0.0))
    )
    blind = dataclasses.replace(cfg, reveal=Reveal.NONE)
    env = cfg.make_task_env()
    print("offset_mm | dropped, off along -x | held, scripted policy: " + " | ".join(DIRECTIONS))
    for mm in args.offsets:
        d = mm / 1000
        held = " | ".join(insert(blind, d * u) for u in DIRECTIONS.values())
        print(f"{mm:g} | {drop(env, d * DIRECTIONS['-x'])} | {held}", flush=True)
    env.close()


if __name__ == "__main__":
    main()
