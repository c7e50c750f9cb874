"""Policies the generator and the evaluator can run: scripted ones and LeRobot checkpoints."""
