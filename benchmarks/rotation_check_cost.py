"""What scipy's validation of a rotation matrix costs, against the conversion the scripted policy runs.

Run:  .venv/bin/python benchmarks/rotation_check_cost.py [--calls 20000] [--repeats 3]

Times, per call on one core (CPU time, median of ``--repeats``), on rotations like the policy's
(products of two random rotations): scipy's ``from_matrix`` with its validation, the same without
it, and ``core.geometry``'s conversion (its own orthonormality check, then scipy's unvalidated
path). Also checks that all three give the same quaternion bits on every matrix timed.
"""

import argparse
import json
import os
import platform
import time

import numpy as np
from scipy.spatial.transform import Rotation
from scipy.spatial.transform import _rotation_cy as compiled

from igen_lerobot.core import geometry


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--calls", type=int, default=20_000)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    os.sched_setaffinity(0, {0})
    a = Rotation.random(args.calls, random_state=1).as_matrix()
    b = Rotation.random(args.calls, random_state=2).as_matrix()
    matrices = list(a @ b.transpose(0, 2, 1))
    ways = {
        "scipy_validated_us": lambda m: compiled.from_matrix(m, assume_valid=False),
        "scipy_unvalidated_us": lambda m: compiled.from_matrix(m, assume_valid=True),
        "geometry_us": geometry._quats_from_matrices,
    }
    reference = [ways["scipy_validated_us"](m) for m in matrices]
    for name, way in ways.items():
        if not all(np.array_equal(way(m), q) for m, q in zip(matrices, reference, strict=True)):
            raise SystemExit(f"{name} differs from scipy's validated conversion")
    timings = {name: [] for name in ways}
    for _ in range(args.repeats):
        for name, way in ways.items():
            t0 = time.process_time()
            for m in matrices:
                way(m)
            timings[name].append(1e6 * (time.process_time() - t0) / args.calls)
    result = {"machine": f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores"}
    result.update({name: float(np.median(values)) for name, values in timings.items()})
    print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
