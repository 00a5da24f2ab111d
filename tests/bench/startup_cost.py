#!/usr/bin/env python3
"""What loading OpenCV's image codecs costs a process, in one run: the median wall time of
`omnical project` (one point; reads no image, so never loads the codecs plugin,
model/io/codecs/image_codecs.h) against `omnical target` writing a small PNG (which loads
it), runs interleaved. With --check, fails unless the plain call takes under a third of the
codec-loading one: the codecs' ~240 shared libraries took ~0.25 s of every process's start
while they were linked, against ~0.03 s for the rest.

Usage: startup_cost.py OMNICAL_BINARY SOURCE_DIR [--runs N] [--check]
"""
import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("omnical")
    parser.add_argument("source_dir")
    parser.add_argument("--runs", type=int, default=15)
    parser.add_argument("--check", action="store_true")
    args = parser.parse_args()
    data = os.path.join(args.source_dir, "datasets-synthetic")
    with tempfile.TemporaryDirectory() as work:
        points = os.path.join(work, "points.csv")
        with open(points, "w") as f:
            f.write("400,-150,60\n")
        plain = [args.omnical, "project", "--sensor", os.path.join(data, "sensors", "ohte-sph.yaml"), "--points", points,
                 "--out", os.path.join(work, "pixels.csv")]
        codecs = [args.omnical, "-q", "target", "--spec", os.path.join(data, "targets", "aprilgrid-6x6-30mm.yaml"),
                  "--dpi", "10", "--out", os.path.join(work, "target.png")]
        times = {"plain": [], "codecs": []}
        for _ in range(args.runs):
            for name, command in (("plain", plain), ("codecs", codecs)):
                start = time.perf_counter()
                done = subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
                times[name].append(time.perf_counter() - start)
                if done.returncode != 0:
                    sys.exit(f"startup_cost: {' '.join(command)} exited {done.returncode}: {done.stderr.strip()}")
    plain_s, codecs_s = statistics.median(times["plain"]), statistics.median(times["codecs"])
    ratio = plain_s / codecs_s
    print(f"omnical project (no image codecs): {1000 * plain_s:.1f} ms; omnical target to PNG (loads the codecs "
          f"plugin): {1000 * codecs_s:.1f} ms; ratio {ratio:.2f} (medians of {args.runs})")
    if args.check and not ratio < 1 / 3:
        sys.exit(f"startup_cost: a call that reads no image took {ratio:.2f} of one that loads the codecs (bound 1/3): "
                 "are imgcodecs or videoio linked again?")


if __name__ == "__main__":
    main()
