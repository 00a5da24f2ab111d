#!/usr/bin/python3
"""How much the two-halves difference depends on which halves: omnical calibrated on the
even/odd halves of a set (what `calibrate --cross-validate` reports) and on random
half-splits, each pair compared with `omnical.diff` at one distance over the observed
field (after the best rigid alignment), RMS per grid point in px.

Usage (omnical's Python module on PYTHONPATH, Debian's interpreter):
  PYTHONPATH=build/test/python /usr/bin/python3 tests/bench/mrcal_compare/random_splits.py \\
      --target tests/data/mei-parabolic-checkerboard.yaml --detections DIR/detections.json [--splits 10]
(detections.json from `omnical calibrate --images ...`; ~1 s per split on 2 cores.)
"""
import argparse
import json
import os
import random
import sys
import tempfile

import numpy as np

import omnical

sys.dont_write_bytecode = True  # no __pycache__ beside the sources
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from omnical_runs import write_detections  # noqa: E402


def fit(target, data, indices, scratch):
    path = os.path.join(scratch, "half.json")
    write_detections(data, {data["images"][i]["image"] for i in indices}, path)
    return omnical.calibrate(target, detections=omnical.Detections.load(path), board_warp=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--target", required=True)
    parser.add_argument("--detections", required=True)
    parser.add_argument("--splits", type=int, default=10, help="random splits besides even/odd")
    parser.add_argument("--seed", type=int, default=5)
    parser.add_argument("--distance-mm", type=float, default=2000.0)
    args = parser.parse_args()

    with open(args.detections) as handle:
        data = json.load(handle)
    views = len(data["images"])
    if views < 4:
        sys.exit(f"{args.detections}: {views} views, need >= 4 for two halves")
    field = omnical.Detections.load(args.detections)
    rng = random.Random(args.seed)
    even_odd = (list(range(0, views, 2)), list(range(1, views, 2)))
    splits, seen = [even_odd], {tuple(even_odd[0]), tuple(even_odd[1])}
    for _ in range(1000 * args.splits):
        if len(splits) > args.splits:
            break
        half = sorted(rng.sample(range(views), views // 2))
        other = [i for i in range(views) if i not in half]
        if tuple(half) in seen or tuple(other) in seen:
            continue
        seen.update({tuple(half), tuple(other)})
        splits.append((half, other))
    diffs = []
    with tempfile.TemporaryDirectory() as scratch:
        for a, b in splits:
            first, second = fit(args.target, data, a, scratch), fit(args.target, data, b, scratch)
            diff = omnical.diff(first.sensor, second.sensor, distance_mm=args.distance_mm, field=field)
            diffs.append(float(diff["rms_px"]))
            print(f"halves {a} / {b}: {diffs[-1]:.3f} px RMS at {args.distance_mm:g} mm", flush=True)
    others = np.array(diffs[1:])
    print(f"even/odd {diffs[0]:.3f} px; {len(others)} random splits: median {np.median(others):.3f}, "
          f"range {others.min():.3f}-{others.max():.3f} px")


if __name__ == "__main__":
    main()
