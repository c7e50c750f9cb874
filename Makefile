# The two commands of the README. Both set up the machine first (scripts/setup.sh is idempotent).
.PHONY: setup demo test lint

export MUJOCO_GL ?= egl

setup:
	@bash scripts/setup.sh

demo: setup
	@bash scripts/demo.sh

test: setup
	@.venv/bin/python -m pytest

lint: setup
	@.venv/bin/ruff check .
