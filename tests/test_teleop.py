"""A person at LeRobot's keyboard teleoperator, driven on a virtual X display, on each of the five tasks.

Real parts only: Xvfb is a real X server, xdotool sends real key events through it, pynput
(inside LeRobot's ``KeyboardEndEffectorTeleop``) receives them. The "person" holds the Up arrow
from step 8 to step 20 of an episode in which the base policy is acting.
"""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

SESSION = r"""
import json, os, subprocess, time
import numpy as np
from lerobot.teleoperators.keyboard.configuration_keyboard import KeyboardEndEffectorTeleopConfig
from lerobot.teleoperators.keyboard.teleop_keyboard import KeyboardEndEffectorTeleop
from igen_lerobot.core.agents import Operator
from igen_lerobot.collection.record import record_intervention
from igen_lerobot.core.env_config import task_config_class
from igen_lerobot.collection.teleop import TeleopOperator

PRESS, RELEASE = 8, 20
cfg = task_config_class(os.environ["IGEN_TASK"])()
env = cfg.make_task_env()
teleop = KeyboardEndEffectorTeleop(KeyboardEndEffectorTeleopConfig())
person = TeleopOperator(teleop, step_m=0.02)
person.connect()
assert teleop.listener is not None, "pynput cannot capture this X display"
time.sleep(0.3)

def key(action):
    subprocess.run(["xdotool", action, "Up"], check=True)
    deadline = time.time() + 5
    while teleop.event_queue.empty() and time.time() < deadline:
        time.sleep(0.005)
    assert not teleop.event_queue.empty(), "the key event never reached pynput"

class Hands(Operator):
    # presses and releases at fixed steps, then lets the real teleop operator judge
    def __init__(self): self.t = 0
    def reset(self, env): self.t = 0; person.reset(env)
    def wants_control(self, env, in_control):
        if self.t == PRESS: key("keydown")
        if self.t == RELEASE: key("keyup")
        self.t += 1
        return person.wants_control(env, in_control)
    def act(self, env): return person.act(env)

episode = record_intervention(env, cfg.make_scripted_policy(), Hands(), seed=0, max_steps=30)
person.close()
print(json.dumps({"flags": episode.is_intervention.tolist(), "source": episode.source.tolist(),
                  "action": episode.action.tolist(), "eef_y": episode.state[:, 1].tolist()}))
"""


@pytest.mark.parametrize("task", ["block_grasp", "nut_insertion", "two_piece_assembly", "coffee", "nut_and_peg"])
def test_holding_a_key_takes_over_and_releasing_hands_back(x_display, task):
    env = {**os.environ, "DISPLAY": x_display, "MUJOCO_GL": "egl", "IGEN_TASK": task}
    result = subprocess.run([sys.executable, "-c", SESSION], env=env, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr[-3000:]
    out = json.loads(result.stdout.strip().splitlines()[-1])
    flags, source = np.array(out["flags"]), np.array(out["source"])
    action, eef_y = np.array(out["action"]), np.array(out["eef_y"])
    expected = np.zeros(len(flags), dtype=bool)
    expected[8:20] = True
    np.testing.assert_array_equal(flags, expected)  # exactly the frames the key was held
    np.testing.assert_array_equal(source[flags], 1)  # operator
    np.testing.assert_array_equal(source[~flags], 0)  # policy before and after
    # LeRobot's keyboard maps Up to delta_y = -1: the person drives the goal 2 cm towards -y
    np.testing.assert_allclose(action[flags, 1], -0.02, atol=1e-6)
    np.testing.assert_allclose(action[flags, [0]], 0.0, atol=1e-6)
    if action.shape[1] == 7:  # 6-DOF tasks: the keys move the hand's position, its orientation is held
        np.testing.assert_allclose(action[flags, 3:6], 0.0, atol=1e-6)
    assert eef_y[20] < eef_y[8] - 0.02
