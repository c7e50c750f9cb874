"""The cameras every Panda table-top task renders: our names -> the compiled scene's MuJoCo cameras.

``agentview`` (robosuite's third-person view of the table from the robot's side) and ``wrist``
(the hand camera) are what vision policies usually train on; the other fixed views are there for
inspection. Importable without MuJoCo (task specs list the names).
"""

PANDA_CAMERAS = {
    "agentview": "agentview",
    "wrist": "robot0_eye_in_hand",
    "frontview": "frontview",
    "sideview": "sideview",
    "birdview": "birdview",
}
