"""franky-sim's FR3 server on one loopback address, optionally with a 5 cm cube on the floor.

Runs in this folder's own environment (mujoco 4): ``tools/franky_sim/.venv/bin/python
tools/franky_sim/serve.py --hostname 127.0.0.1 [--cube 0.5 0.0]``. It is what
``python -m franky_sim.run_server --simulator mujoco --hostname ...`` runs, plus the cube
(the standard server has an empty scene). Prints ``READY`` once the robot answers.
"""

import argparse
import xml.etree.ElementTree as ET

import franky_sim
from franky_sim.mujoco_simulator import MujocoSimulator


def main() -> None:
    """Build the scene, serve the robot until killed."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--hostname", default="127.0.0.1")
    parser.add_argument("--cube", type=float, nargs=2, default=None, metavar=("X", "Y"), help="cube position [m]")
    args = parser.parse_args()
    with MujocoSimulator(enable_visualization=False) as sim:
        if args.cube is not None:
            x, y = args.cube
            cube = ET.SubElement(sim.worldbody, "body", name="cube", pos=f"{x} {y} 0.025")
            ET.SubElement(cube, "freejoint", name="cube_joint")
            box = {"type": "box", "size": "0.025 0.025 0.025", "rgba": "1 0 0 1", "mass": "0.1"}
            ET.SubElement(cube, "geom", friction="1.5 0.01 0.001", **box)
        sim.add_robot()
        with franky_sim.SimulationServer(sim, hostname_candidates=[args.hostname]) as server:
            print("READY", flush=True)
            server.run_forever()


if __name__ == "__main__":
    main()
