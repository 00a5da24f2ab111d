#!/usr/bin/env python3
"""omnical.Sensor.project on 10^6 points from NumPy against the C++ batch API
(Sensor::ProjectBatch) on the same points, in the same run: the two are timed in
alternation (fastest of each), and the ratio Python / C++ must stay under 1.3 (no
per-point Python overhead). Points: rays of a pixel grid over the mirror, at 200-5000 mm,
so that nearly all project (the work users time). The C++ side takes its fastest of
three repeats per process, as warm as the Python side.

Usage: python_project_bench.py BATCH_PROJECT_TIME_BINARY SENSOR.yaml [SENSOR.yaml ...]
Environment: PYTHONPATH with the omnical package.
"""
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

import omnical

COUNT = 1_000_000
ROUNDS = 3
BOUND = 1.3


def points_seen_by(sensor, count, rng):
    width, height = sensor.image_size
    pixels = np.column_stack([rng.uniform(0, width - 1, 4 * count), rng.uniform(0, height - 1, 4 * count)])
    origins, directions, status = sensor.unproject(pixels)
    keep = status == omnical.ProjectionStatus.OK
    origins, directions = origins[keep][:count], directions[keep][:count]
    distances = rng.uniform(200.0, 5000.0, len(origins))[:, None]
    return np.ascontiguousarray(origins + distances * directions)


def main():
    binary, sensors = sys.argv[1], sys.argv[2:]
    rng = np.random.default_rng(18)
    worst = 0.0
    for path in sensors:
        sensor = omnical.Sensor.load(path)
        points = points_seen_by(sensor, COUNT, rng)
        assert len(points) == COUNT, f"{path}: only {len(points)} points seen"
        with tempfile.NamedTemporaryFile(suffix=".f64", delete=False) as raw:
            raw.write(points.tobytes())
        try:
            cpp, python = [], []
            for _ in range(ROUNDS):
                out = subprocess.run([binary, path, raw.name, "3"], check=True, capture_output=True, text=True)
                seconds, cpp_ok = out.stdout.split()
                cpp.append(float(seconds))
                start = time.perf_counter()
                _, status = sensor.project(points)
                python.append(time.perf_counter() - start)
                python_ok = int(np.count_nonzero(status == omnical.ProjectionStatus.OK))
                assert python_ok == int(cpp_ok), f"{path}: Python {python_ok} OK points, C++ {cpp_ok}"
        finally:
            os.unlink(raw.name)
        ratio = min(python) / min(cpp)
        worst = max(worst, ratio)
        print(f"{os.path.basename(path)}: {COUNT} points ({python_ok} OK): C++ batch {min(cpp) * 1e3:.1f} ms, "
              f"Python {min(python) * 1e3:.1f} ms, ratio {ratio:.3f} (bound {BOUND})")
    print("1 passed, 0 failed" if worst < BOUND else "0 passed, 1 failed")
    return 0 if worst < BOUND else 1


if __name__ == "__main__":
    sys.exit(main())
