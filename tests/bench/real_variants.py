#!/usr/bin/python3
"""The real dev set as the sets the issue describes would show it: Mei's paracatadioptric
images (1280 x 1024 grey PGM) scaled to 640-1024 px wide (area-averaged), saved as JPEG at
quality 50-90, grey or colour, blurred, dimmed and noisy, or cropped off-centre, each
calibrated as a new user would (`omnical calibrate --images DIR --cross-validate`, no
guess). Per variant: the views used, the corners, the views skipped with omnical's reason,
the RMS (per corner, sqrt(mean |e|^2): inliers and all corners) and the two halves'
difference at 2 m (RMS / max over the observed field, after the best rigid alignment).

Usage (Debian's interpreter, for cv2):
  /usr/bin/python3 tests/bench/real_variants.py --omnical build/test/tools/omnical \\
      [--real-data ../shared/real-data/mei-parabolic] [--keep DIR]
(~10 s per variant on 2 cores; 8 variants.)
"""
import argparse
import glob
import json
import os
import shutil
import subprocess
import sys
import tempfile

import cv2
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TARGET = os.path.join(ROOT, "tests", "data", "mei-parabolic-checkerboard.yaml")


def variants():
    """name -> (what it is, the 8-bit grey source image -> (image to save, JPEG quality))."""
    def scaled(image, scale, interpolation=cv2.INTER_AREA):
        return cv2.resize(image, None, fx=scale, fy=scale, interpolation=interpolation)

    noise = np.random.default_rng(1)

    def blurred_dim_noisy(image):
        half = cv2.GaussianBlur(scaled(image, 0.5), (0, 0), 0.8).astype(float)
        out = np.clip(0.7 * half + 20 + noise.normal(0, 3, half.shape), 0, 255).astype(np.uint8)
        return cv2.cvtColor(out, cv2.COLOR_GRAY2BGR)

    return {
        "1024 px, colour, JPEG 85": lambda g: (cv2.cvtColor(scaled(g, 0.8), cv2.COLOR_GRAY2BGR), 85),
        "800 px, grey, JPEG 85": lambda g: (scaled(g, 0.625), 85),
        "640 px, colour, JPEG 75": lambda g: (cv2.cvtColor(scaled(g, 0.5), cv2.COLOR_GRAY2BGR), 75),
        "640 px, grey, JPEG 90": lambda g: (scaled(g, 0.5), 90),
        "640 px, grey, JPEG 50": lambda g: (scaled(g, 0.5), 50),
        "640 px, nearest-neighbour scaling, JPEG 85": lambda g: (scaled(g, 0.5, cv2.INTER_NEAREST), 85),
        "640 px, blur 0.8 px, 70 % contrast, noise 3, colour, JPEG 85": lambda g: (blurred_dim_noisy(g), 85),
        "640 x 480 px cropped off-centre from 704 px, JPEG 85": lambda g: (scaled(g, 0.55)[40:520, 40:680], 85),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--omnical", required=True, help="the omnical binary")
    parser.add_argument("--real-data", default=os.path.join(ROOT, "..", "shared", "real-data", "mei-parabolic"))
    parser.add_argument("--keep", help="keep each variant's images and calibration under this directory")
    args = parser.parse_args()
    sources = sorted(glob.glob(os.path.join(args.real_data, "*.pgm")))
    if not sources:
        sys.exit(f"real_variants: no .pgm image in {args.real_data}")
    work = args.keep or tempfile.mkdtemp(prefix="omnical-real-variants-")
    print("| variant | views used | corners | views skipped (omnical's reason) | RMS inliers / all (px) "
          "| halves at 2 m, RMS / max (px) |")
    print("| --- | --- | --- | --- | --- | --- |")
    for index, (name, make) in enumerate(variants().items()):
        images = os.path.join(work, f"variant{index}")
        os.makedirs(images, exist_ok=True)
        for path in sources:
            image, quality = make(cv2.imread(path, cv2.IMREAD_GRAYSCALE))
            out = os.path.join(images, os.path.splitext(os.path.basename(path))[0] + ".jpg")
            cv2.imwrite(out, image, [cv2.IMWRITE_JPEG_QUALITY, quality])
        calibration = os.path.join(work, f"calibration{index}")
        done = subprocess.run([args.omnical, "-q", "calibrate", "--target", TARGET, "--images", images,
                               "--cross-validate", "--out", calibration], capture_output=True, text=True)
        if done.returncode != 0:
            last = (done.stderr.strip().splitlines() or [f"exit status {done.returncode}"])[-1]
            print(f"| {name} | calibrate failed: {last} | | | | |")
            continue
        with open(os.path.join(calibration, "calibration.json")) as file:
            record = json.load(file)
        skipped = "; ".join(f"{os.path.basename(image)}: {why}"
                            for image, why in record.get("views_skipped", {}).items())
        halves = record["cross_validation"]
        print(f"| {name} | {len(record['poses'])} of {len(sources)} | {record['observations']} | {skipped or 'none'} "
              f"| {record['rms_px']:.3f} / {record['rms_all_px']:.3f} "
              f"| {halves['diff_rms_px']:.3f} / {halves['diff_max_px']:.3f} |", flush=True)
    if not args.keep:
        shutil.rmtree(work)


if __name__ == "__main__":
    main()
