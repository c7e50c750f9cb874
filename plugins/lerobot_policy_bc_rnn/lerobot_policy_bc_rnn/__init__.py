"""LeRobot plugin entry point for BC-RNN.

LeRobot imports every installed distribution named ``lerobot_policy_*``; the policy itself lives
in the core package (``igen_lerobot.training.bc_rnn``), and importing it registers ``bc_rnn``.
"""

from igen_lerobot.training.bc_rnn import BCRNNConfig

__all__ = ["BCRNNConfig"]
