"""2-Piece Assembly: at what offset from the receptacle's axis the piece seats, and where it rests on the rim.

Two measurements on the task's own scene (MuJoCo, robosuite's ``Bin`` and the ridged slab):

* ``drop``: the piece alone, level, yaw aligned, released at rest with its bottom 1 cm above the
  rim, its centre off the receptacle's by ``d`` along x (and along the diagonal); the arm waits
  away above. After 2 s: the piece bottom's height above the floor, its tilt, and ``seated()``.
* ``insert``: the piece in the hand, the scripted base policy believing the receptacle ``d`` off
  along x (no other error) and never told better (``--env.reveal=none``): it goes straight down and
  lets go once the piece is at the floor. After its 200 steps: success, the first piece-receptacle
  contact (step, height above the rim), and where the piece is.

Run:  MUJOCO_GL=egl .venv/bin/python benchmarks/two_piece_clearance.py [--offsets 0 3 5 6 7 8 10 15 20 30 40]
"""

import argparse
import dataclasses

import numpy as np

from igen_lerobot.core.belief import Reveal
from igen_lerobot.core.error_models import BoxNoise
from lerobot_env_igen.panda import TOP_DOWN_ROT
from lerobot_env_igen.two_piece_assembly.config import TwoPieceAssemblyEnvConfig
from lerobot_env_igen.two_piece_assembly.spec import FLOOR_Z, RECEPTACLE_SIZE, SLAB_HALF, TABLE_TOP_Z

RIM_Z = TABLE_TOP_Z + RECEPTACLE_SIZE[2]


def _state(env) -> tuple[float, float]:
    piece = env.true_object_poses()["piece"]
    tilt = float(np.degrees(np.arccos(np.clip(piece[2, 2], -1.0, 1.0))))
    return float(piece[2, 3] - SLAB_HALF[2] - FLOOR_Z), tilt


def drop(env, offset_xy: np.ndarray) -> dict:
    env.reset(0)
    env.arm.reset()  # fingers open, nothing in the hand
    target = env.true_object_poses()["receptacle"][:3, 3]
    start = np.array([*(target[:2] + offset_xy), RIM_Z + 0.01 + SLAB_HALF[2]])
    env.set_free_pose("piece", start)
    home = env.arm.eef_pos() + np.array([0.0, 0.0, 0.05])
    for _ in range(40):
        env.arm.control_period(home, False, TOP_DOWN_ROT)
    height, tilt = _state(env)
    return {"bottom_above_floor_mm": round(1000 * height, 1), "tilt_deg": round(tilt, 1), "seated": env.seated()}


def insert(cfg, offset: float) -> dict:
    env, policy = cfg.make_task_env(), cfg.make_scripted_policy()
    obs = env.reset(0, corruption=np.array([-offset, 0.0, 0.0]))  # believed = true - offset: it lands +offset
    first = None
    success = False
    for t in range(cfg.episode_length):
        info = env.step(policy.act(obs))
        obs = env.observe()
        if info.revealed and first is None:
            contact = env.last_reveal_contact.position
            first = {"step": t, "contact_z_above_rim_mm": round(1000 * float(contact[2] - RIM_Z), 1)}
        if info.success:
            success = True
            break
    height, tilt = _state(env)
    piece, target = env.true_object_poses()["piece"][:3, 3], env.true_object_poses()["receptacle"][:3, 3]
    env.close()
    return {
        "success": success,
        "first_contact": first,
        "bottom_above_floor_mm": round(1000 * height, 1),
        "tilt_deg": round(tilt, 1),
        "xy_off_mm": round(1000 * float(np.linalg.norm(piece[:2] - target[:2])), 1),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--offsets", type=float, nargs="+", default=[0, 3, 5, 6, 7, 8, 10, 15, 20, 30, 40])
    args = parser.parse_args()
    cfg = dataclasses.replace(
        TwoPieceAssemblyEnvConfig(), corruption=BoxNoise(half_extent=(0.05, 0.05, 0.05), min_abs=(0.0, 0.0, 0.0))
    )
    blind = dataclasses.replace(cfg, reveal=Reveal.NONE)
    env = cfg.make_task_env()
    print("offset_mm | drop along x | drop along the diagonal | held, scripted policy")
    for mm in args.offsets:
        d = mm / 1000
        along_x = drop(env, np.array([d, 0.0]))
        diagonal = drop(env, np.array([d, d]) / np.sqrt(2))
        print(f"{mm:g} | {along_x} | {diagonal} | {insert(blind, d)}", flush=True)
    env.close()


if __name__ == "__main__":
    main()
