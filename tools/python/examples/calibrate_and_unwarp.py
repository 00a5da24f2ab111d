#!/usr/bin/env python3
"""omnical from Python, end to end on the bundled rendered set: calibrate the non-central
model from the images, print the parameters, plot the residuals and the parallax curve
(matplotlib), and unwarp one view to a panorama with cv2.remap through tables exact for
objects 7 mirror radii away.

Run from anywhere after the README's build (scripts/demo.sh or scripts/test.sh):
    PYTHONPATH=build/demo/python python3 tools/python/examples/calibrate_and_unwarp.py example-out
Writes OUT/calibration/ (what `omnical calibrate` writes), OUT/residuals.png,
OUT/parallax.png and OUT/panorama.png.
"""
import argparse
import pathlib
import sys

import cv2
import matplotlib

matplotlib.use("Agg")  # files only: no display needed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import omnical  # noqa: E402

DATA = pathlib.Path(__file__).resolve().parents[3] / "datasets-synthetic"


def terminal_progress(quiet):
    """Progress on a terminal, one line per stage; nothing when quiet or not a terminal."""
    if quiet or not sys.stderr.isatty():
        return None

    def report(stage, done, total):
        sys.stderr.write(f"\r{stage}: {done}/{total}" if total else f"\r{stage}: {done}")
        if total and done == total:
            sys.stderr.write("\n")
    return report


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", type=pathlib.Path, nargs="?", default=pathlib.Path("example-out"))
    parser.add_argument("--images", type=pathlib.Path, default=DATA / "rendered" / "ohte-sph-near")
    parser.add_argument("--guess", type=pathlib.Path, default=DATA / "sensors" / "ohte-sph.yaml")
    parser.add_argument("--target", type=pathlib.Path, default=DATA / "targets" / "aprilgrid-6x6-30mm.yaml")
    parser.add_argument("-q", "--quiet", action="store_true")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)

    # 1. Calibrate: detect the aprilgrid in every image, fit from the design guess with the
    #    lens distortion held, and predict the projection error 7 mirror radii away.
    result = omnical.calibrate(args.target, args.images, guess=args.guess, fixed=["distortion"], distances_n=[7],
                               progress=terminal_progress(args.quiet))
    result.save(args.out / "calibration")
    print(f"{len(result.views)} views: RMS {result.rms_px:.4f} px per corner "
          f"({'converged' if result.converged else 'NOT converged'})")
    for name, parameter in result.parameters.items():
        spread = "(fixed)" if parameter.fixed else f"+- {parameter.std:.3g}"
        print(f"  {name:16s} {parameter.value:14.8g} {spread}")
    for warning in result.warnings:
        print(f"warning: {warning.text}")

    # 2. Residuals: every corner's residual vector, and their lengths.
    residuals = np.vstack([errors for _, errors in result.residuals.values()])
    figure, (scatter, histogram) = plt.subplots(1, 2, figsize=(10, 4.5))
    scatter.scatter(residuals[:, 0], residuals[:, 1], s=2)
    scatter.set(xlabel="u residual (px)", ylabel="v residual (px)", title="residual per corner", aspect="equal")
    histogram.hist(np.linalg.norm(residuals, axis=1), bins=50)
    histogram.set(xlabel="|residual| (px)", ylabel="corners", title=f"RMS {result.rms_px:.4f} px")
    figure.tight_layout()
    figure.savefig(args.out / "residuals.png", dpi=100)

    # 3. Parallax: how far a central projector misplaces objects 7 mirror radii away.
    parallax = omnical.parallax(result.sensor, n=7)
    figure, axes = plt.subplots(figsize=(6, 4))
    axes.plot(parallax.omega_deg, parallax.error_px)
    axes.set(xlabel="Omega, ray angle from the mirror axis (deg)", ylabel="error (px)",
             title=f"objects at n = 7 ({parallax.distance_mm:.0f} mm), V0 = {parallax.v0_mm:.2f} mm")
    figure.tight_layout()
    figure.savefig(args.out / "parallax.png", dpi=100)
    print(f"parallax at n = 7: up to {parallax.max_abs_error_px:.3f} px for a central model")

    # 4. A panorama exact for objects 7 mirror radii away, applied with OpenCV.
    map_x, map_y = omnical.remap_tables(result.sensor, "panorama", n=7, size=(1024, 256))
    image = cv2.imread(str(sorted(args.images.glob("*.png"))[0]))
    panorama = cv2.remap(image, map_x, map_y, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT)
    cv2.imwrite(str(args.out / "panorama.png"), panorama)
    print(f"-> {args.out}: calibration/, residuals.png, parallax.png, panorama.png")


if __name__ == "__main__":
    main()
