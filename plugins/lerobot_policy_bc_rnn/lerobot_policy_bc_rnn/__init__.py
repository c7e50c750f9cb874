"""LeRobot plugin entry point for BC-RNN.

LeRobot imports every installed distribution named ``lerobot_policy_*``; the policy itself lives
in the core package (``igen_lerobot.training.bc_rnn``), and importing it registers ``bc_rnn``.
Importing it also installs the frame cache (``igen_lerobot.training.frame_cache``: the same
samples, read about 25 times faster; ``IGEN_FRAME_CACHE=0`` turns it off) and the resume-order
fix (``igen_lerobot.training.resume_order``: a run resumed after its first epoch continues the
data order of the run it resumes), in every ``lerobot-train``, whatever its policy.
"""

from igen_lerobot.training import frame_cache, resume_order
from igen_lerobot.training.bc_rnn import BCRNNConfig

frame_cache.install()
resume_order.install()

__all__ = ["BCRNNConfig"]
