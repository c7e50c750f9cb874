"""The ``igen-deploy`` console command: started again on the tables' code paths, as every igen command.

A rehearsal typed by hand (MuJoCo arm, rendered camera) then computes what the table's rehearsal
step computed (``igen_lerobot.scripts.console``).
"""

from igen_lerobot.scripts.console import start


def igen_deploy() -> None:
    """``igen-deploy``."""
    start("lerobot_robot_igen.deploy.igen_deploy")
