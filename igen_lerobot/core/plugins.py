"""LeRobot's plugin discovery, once per process.

``register_third_party_plugins`` reads the metadata of every installed distribution on each call
(about 0.25 s with this environment's ~250), and a table step asks for a task's config a dozen
times. What it imports stays imported, so a second call in the same process finds nothing new.
"""

from functools import cache


@cache
def discover_plugins() -> None:
    """Import every installed ``lerobot_*`` plugin (tasks, the BC-RNN policy, the robot) the first time."""
    from lerobot.utils.import_utils import register_third_party_plugins

    register_third_party_plugins()
