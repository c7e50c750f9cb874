"""LeRobot plugin entry point for BC-RNN.

LeRobot imports every installed distribution named ``lerobot_policy_*``; the policy itself lives
in the core package (``igen_lerobot.training.bc_rnn``), and importing it registers ``bc_rnn``.
Importing it also installs the frame cache (``igen_lerobot.training.frame_cache``: the same
samples, read about 25 times faster; ``IGEN_FRAME_CACHE=0`` turns it off).
"""

from igen_lerobot.training import frame_cache
from igen_lerobot.training.bc_rnn import BCRNNConfig

frame_cache.install()

__all__ = ["BCRNNConfig"]
