"""franky-sim's FR3 server on one loopback address, optionally with a 5 cm cube on the floor.

Runs in this folder's own environment (mujoco 4): ``tools/franky_sim/.venv/bin/python
tools/franky_sim/serve.py --hostname 127.0.0.1 [--cube 0.5 0.0] [--scene-port 7711]``. It is what
``python -m franky_sim.run_server --simulator mujoco --hostname ...`` runs, plus the cube
(the standard server has an empty scene). Prints ``READY`` once the robot answers.

``--scene-port`` also serves the cube over TCP on the same address, one JSON object per line:
``{"cmd": "cube"}`` answers its pose (``pos`` [m], ``quat_wxyz``, robot base frame) and
``{"cmd": "place", "x": .., "y": .., "yaw": ..}`` puts it back on the floor there, at rest. This
stands in for the camera a real cell has (franky-sim renders none) and lets a rehearsal place the
cube per trial without restarting the robot.

franky-sim reports the external wrench ``O_F_ext_hat_K`` as zeros, so an arm touching the cube
would never feel it and the deployment loop's force-based contact (which reveals the true pose)
could not fire. This server fills its force part with the net contact force that everything
outside the robot exerts on the hand and fingers (MuJoCo's contact forces, base frame): what a
real arm's FCI estimates from joint torques, without its bias and noise. The driver reads it
through the libfranka protocol exactly as on a real arm.
"""

import argparse
import json
import math
import socketserver
import threading
import xml.etree.ElementTree as ET

import franky_sim
import mujoco
import numpy as np
from franky_sim.mujoco_simulator import FrankaMujocoRobot, MujocoSimulator

HAND_BODIES = ("hand", "left_finger", "right_finger")  # after franky-sim's robot prefix
# The Block Grasp cube as the training simulator builds it (robosuite's BoxObject defaults:
# density 1000, so 0.125 kg; its friction and contact softness), so the fingers push, tip and
# hold it as they did in training.
TRAINING_CUBE = {
    "type": "box",
    "size": "0.025 0.025 0.025",
    "rgba": "1 0 0 1",
    "mass": "0.125",
    "friction": "1 0.005 0.0001",
    "solref": "0.02 1",
    "solimp": "0.9 0.95 0.001",
}


def main() -> None:
    """Build the scene, serve the robot until killed."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--hostname", default="127.0.0.1")
    parser.add_argument("--cube", type=float, nargs=2, default=None, metavar=("X", "Y"), help="cube position [m]")
    parser.add_argument("--scene-port", type=int, default=None, help="serve the cube's pose and placement here")
    args = parser.parse_args()
    _report_hand_contact_wrench()
    with MujocoSimulator(enable_visualization=False) as sim:
        if args.cube is not None:
            x, y = args.cube
            cube = ET.SubElement(sim.worldbody, "body", name="cube", pos=f"{x} {y} 0.025")
            ET.SubElement(cube, "freejoint", name="cube_joint")
            ET.SubElement(cube, "geom", **TRAINING_CUBE)
        sim.add_robot()
        with franky_sim.SimulationServer(sim, hostname_candidates=[args.hostname]) as server:
            if args.scene_port is not None and args.cube is not None:
                scene = socketserver.ThreadingTCPServer((args.hostname, args.scene_port), _scene_handler(sim))
                scene.daemon_threads = True
                threading.Thread(target=scene.serve_forever, name="cube-scene", daemon=True).start()
            print("READY", flush=True)
            server.run_forever()


def hand_contact_force(model, data, hand: set[int], robot_root: int) -> np.ndarray:
    """Net force [N, world = base frame] that bodies outside the robot exert on the ``hand`` bodies."""
    total = np.zeros(3)
    wrench = np.zeros(6)
    for i in range(data.ncon):
        contact = data.contact[i]
        body1, body2 = model.geom_bodyid[contact.geom1], model.geom_bodyid[contact.geom2]
        on_hand1, on_hand2 = body1 in hand, body2 in hand
        robot1, robot2 = model.body_rootid[body1] == robot_root, model.body_rootid[body2] == robot_root
        if robot1 == robot2 or not (on_hand1 or on_hand2):
            continue  # robot-robot, world-world, or a contact on the arm's links (not the hand)
        mujoco.mj_contactForce(model, data, i, wrench)
        force = contact.frame.reshape(3, 3).T @ wrench[:3]  # on geom2, pushed along the normal from geom1
        total += force if on_hand2 else -force
    return total


def _report_hand_contact_wrench() -> None:
    """Make franky-sim's robot state carry the hand's contact force as ``O_F_ext_hat_K`` (see module doc)."""
    original = FrankaMujocoRobot.state

    def state(robot):
        snapshot = original.fget(robot)
        model, data = robot.model, robot.data
        if model is None or data is None:
            return snapshot
        bodies = getattr(robot, "_igen_hand_bodies", None)  # found once: this runs every 1 ms control cycle
        if bodies is None:
            names = {model.body(i).name: i for i in range(model.nbody)}
            hand = {i for name, i in names.items() if name.endswith(HAND_BODIES) and name.startswith("robot")}
            bodies = robot._igen_hand_bodies = (hand, int(model.body_rootid[next(iter(hand))]))
        force = hand_contact_force(model, data, *bodies)
        return snapshot.replace(O_F_ext_hat_K=(*force.tolist(), 0.0, 0.0, 0.0))

    FrankaMujocoRobot.state = property(state)


def _scene_handler(sim):
    """A request handler answering "cube" and "place" for the cube of ``sim``."""

    class Handler(socketserver.StreamRequestHandler):
        def handle(self) -> None:
            for line in self.rfile:
                request = json.loads(line)
                model, data = sim.model, sim.data
                body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "cube")
                joint = model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "cube_joint")]
                dof = model.jnt_dofadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "cube_joint")]
                if request["cmd"] == "cube":
                    reply = {"pos": data.xpos[body].tolist(), "quat_wxyz": data.xquat[body].tolist()}
                elif request["cmd"] == "place":
                    half = request.get("yaw", 0.0) / 2
                    data.qpos[joint : joint + 7] = [
                        request["x"],
                        request["y"],
                        0.025,
                        math.cos(half),
                        0,
                        0,
                        math.sin(half),
                    ]
                    data.qvel[dof : dof + 6] = 0.0
                    reply = {"ok": True}
                else:
                    reply = {"error": f"unknown cmd {request['cmd']!r}; use cube or place"}
                self.wfile.write((json.dumps(reply) + "\n").encode())

    return Handler


if __name__ == "__main__":
    main()
