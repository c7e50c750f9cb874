# The two commands of the README. Both set up the machine first (scripts/setup.sh is idempotent).
.PHONY: setup demo test lint

export MUJOCO_GL ?= egl

setup:
	@bash scripts/setup.sh

demo: setup
	@bash scripts/demo.sh

# Two passes: everything but the wall-clock robot tests on both cores (pytest-xdist, one file per
# worker), then the `realtime` ones alone so nothing steals the cycles their timing depends on.
# --max-worker-restart=0: a worker ended by the per-test ceiling fails the run at once; xdist 3.8's
# loadfile scheduling hangs after replacing a crashed worker (pytest-xdist#784, #1323).
# One compute thread per worker and its subprocesses (a step that names its own count, as a table's
# training does, keeps it): two 2-thread torch pools on two cores wait on each other
# (docs/benchmarks.md, "Never run two trainings at once"); measured on two torch-heavy files,
# 168 s at torch's default against 145 s at one thread.
test: setup
	@OMP_NUM_THREADS=1 MKL_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 \
		.venv/bin/python -m pytest -n 2 --dist loadfile --max-worker-restart=0 -m "not realtime"
	@.venv/bin/python -m pytest -m realtime

lint: setup
	@.venv/bin/ruff check .
