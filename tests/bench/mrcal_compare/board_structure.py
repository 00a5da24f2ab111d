"""Does a calibration leave a board shape in its residuals that recurs across views?

The image-plane fields of residual_structure.py look for an error tied to the pixel (the
sensor's); a board that is not the shape the fit assumed errs at the same *corner* in every
view instead, wherever that corner lands in the image. So here each corner of the board gets
its own out-of-plane offset (mm, shared by every view: the board's relief,
calib/board_warp.h), its effect on each view's corners linearised through the calibration
(the projection's derivative along the board's normal, by finite differences through the
written sensor.yaml and poses), fitted to the residuals by ridge least squares (each offset
a Gaussian prior of `--prior-mm`, as calibrate's relief), learnt on every view but one and
applied to the one left out, every view in turn. The held-out RMS against the RMS with no
offsets says whether the residuals hold a board shape that other views predict.

    python3 board_structure.py CALIBRATION_DIR TARGET_YAML [--detections FILE] [--prior-mm S]

With omnical's Python module on PYTHONPATH (e.g. build/test/python). CALIBRATION_DIR is
calibrate's --out (calibration.json, sensor.yaml, detections.json when
calibrated from images). Prints the figures as JSON; RMS per corner, sqrt(mean |e|^2), px.
Measured this way the Mei dev set's warp-only calibration (`--board-relief off`) gave
0.286 px with no offsets and 0.223 held out (docs/calibrate.md, "Bent boards").
"""
import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import omnical_runs  # noqa: E402

STEP_MM = 0.05


def linearised_offsets(calibration, board, views):
    """Per corner: residual (2), d pixel / d normal offset (2), corner id, view index."""
    sensor = os.path.join(calibration["_dir"], "sensor.yaml")
    rows = []
    for index, view in enumerate(views):
        pose = calibration["poses"].get(view["image"])
        if pose is None:
            continue
        rotation = omnical_runs._rotation_wxyz(pose["camera_from_target_quaternion_wxyz"])
        translation = np.array(pose["camera_from_target_translation_mm"], dtype=float)
        offsets = omnical_runs.board_warp_offsets_mm(calibration, board, view["ids"])
        points = np.array([(*board.points_mm[i], z) for i, z in zip(view["ids"], offsets)])
        pixels = omnical_runs._project(None, sensor, points @ rotation.T + translation)
        moved = points.copy()
        moved[:, 2] += STEP_MM
        slope = (omnical_runs._project(None, sensor, moved @ rotation.T + translation) - pixels) / STEP_MM
        for k, corner_id in enumerate(view["ids"]):
            rows.append((pixels[k] - view["pixels"][k], slope[k], corner_id, index))
    keep = [r for r in rows if np.all(np.isfinite(r[0])) and np.all(np.isfinite(r[1]))]
    return (np.array([r[0] for r in keep]), np.array([r[1] for r in keep]), np.array([r[2] for r in keep]),
            np.array([r[3] for r in keep]))


def held_out_offsets(residuals, slopes, ids, view_of, prior_mm):
    """RMS with no offsets, with offsets learnt on the other views (each view in turn) and
    in-sample, and the in-sample offsets' RMS (mm)."""
    columns = {c: k for k, c in enumerate(sorted(set(ids.tolist())))}
    design = np.zeros((2 * len(ids), len(columns)))
    for i, corner_id in enumerate(ids):
        design[2 * i:2 * i + 2, columns[corner_id]] = slopes[i]
    y = residuals.reshape(-1)
    rows = np.repeat(view_of, 2)
    sigma_px = np.sqrt(np.mean(y ** 2))  # per coordinate: the prior weighs against the corner noise
    ridge = (sigma_px / prior_mm) ** 2

    def solve(mask):
        a = design[mask]
        return np.linalg.solve(a.T @ a + ridge * np.eye(a.shape[1]), a.T @ y[mask])

    predicted = np.zeros_like(y)
    for view in np.unique(view_of):
        out = rows == view
        predicted[out] = design[out] @ solve(~out)
    everything = solve(np.ones(len(y), bool))
    per_corner = lambda e: float(np.sqrt(2.0 * np.mean(e ** 2)))  # noqa: E731
    return dict(none_px=per_corner(y), held_out_px=per_corner(y - predicted), in_sample_px=per_corner(y - design @ everything),
                offsets_rms_mm=float(np.sqrt(np.mean(everything ** 2))), corners=int(len(ids)),
                views=int(len(np.unique(view_of))))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("calibration_dir")
    parser.add_argument("target")
    parser.add_argument("--detections", help="default: CALIBRATION_DIR/detections.json")
    parser.add_argument("--prior-mm", type=float, default=1.0)
    args = parser.parse_args()
    try:
        calibration = omnical_runs.read_json(os.path.join(args.calibration_dir, "calibration.json"))
        calibration["_dir"] = args.calibration_dir
        board = omnical_runs.Board(args.target)
        _, _, views = omnical_runs.read_detections(args.detections or os.path.join(args.calibration_dir, "detections.json"))
        found = held_out_offsets(*linearised_offsets(calibration, board, views), args.prior_mm)
    except (omnical_runs.BenchError, OSError, KeyError, ValueError) as error:
        sys.exit(f"board_structure: {error}")
    print(json.dumps(found, indent=1))


if __name__ == "__main__":
    main()
