"""BC-RNN (robomimic's recurrent behaviour cloning with a GMM action head) as a LeRobot policy.

Importing this package registers ``--policy.type=bc_rnn`` with LeRobot; LeRobot finds the
modeling and processor modules by its ``configuration_* -> modeling_* / processor_*`` naming.
"""

from igen_lerobot.training.bc_rnn.configuration_bc_rnn import BCRNNConfig

__all__ = ["BCRNNConfig"]
