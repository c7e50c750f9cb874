"""The ``igen-*`` console scripts: they parse arguments and call library functions.

They render headless unless told otherwise: MuJoCo picks its OpenGL backend when it is first
imported, so the default (EGL; Mesa's software renderer where there is no GPU) is set here, before
any script imports the simulator. ``MUJOCO_GL=glfw`` still selects an on-screen context.
"""

import os

os.environ.setdefault("MUJOCO_GL", "egl")
