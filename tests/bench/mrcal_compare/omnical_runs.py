"""The omnical side of the comparison: the CLI runs, the corners they detect, the board
layout behind corner ids, and per-corner residuals of a calibration.json."""
import json
import math
import os
import re
import subprocess
import tempfile
import time

import numpy as np


class BenchError(Exception):
    """A one-line message naming the file (or command) at fault."""


# ---------------------------------------------------------------------------- board

def _spec_value(path, spec, key, default=None):
    if key not in spec:
        if default is not None:
            return default
        raise BenchError(f"{path}: missing '{key}'")
    return spec[key]


def read_target_spec(path):
    """Kalibr-key YAML (flat key: value lines; the omnical specs carry nothing else)."""
    spec = {}
    try:
        with open(path) as handle:
            for line in handle:
                line = line.split("#", 1)[0].strip()
                if not line:
                    continue
                key, sep, value = line.partition(":")
                if not sep:
                    raise BenchError(f"{path}: cannot read line '{line}'")
                value = value.strip().strip("'\"")
                try:
                    spec[key.strip()] = float(value)
                except ValueError:
                    spec[key.strip()] = value
    except OSError as error:
        raise BenchError(f"{path}: {error.strerror}")
    return spec


def board_points_mm(path):
    """Corner id -> board point (mm), as calib/target.cc numbers them: checkerboard
    id = row * targetCols + col at (col * colSpacing, row * rowSpacing); aprilgrid
    id = 4 * tag + k, tag = codeOffset + row * tagCols + col, k = 0..3 the black
    square's corners (x, y), (x + s, y), (x + s, y + s), (x, y + s), pitch s (1 + tagSpacing)."""
    spec = read_target_spec(path)
    kind = _spec_value(path, spec, "target_type")
    points = {}
    if kind == "checkerboard":
        cols, rows = int(_spec_value(path, spec, "targetCols")), int(_spec_value(path, spec, "targetRows"))
        col_mm = 1000.0 * _spec_value(path, spec, "colSpacingMeters")
        row_mm = 1000.0 * _spec_value(path, spec, "rowSpacingMeters")
        for row in range(rows):
            for col in range(cols):
                points[row * cols + col] = (col * col_mm, row * row_mm)
    elif kind == "aprilgrid":
        cols, rows = int(_spec_value(path, spec, "tagCols")), int(_spec_value(path, spec, "tagRows"))
        size = 1000.0 * _spec_value(path, spec, "tagSize")
        pitch = size * (1.0 + _spec_value(path, spec, "tagSpacing"))
        offset = int(spec.get("codeOffset", 0))
        for row in range(rows):
            for col in range(cols):
                tag, x, y = offset + row * cols + col, col * pitch, row * pitch
                for k, corner in enumerate(((x, y), (x + size, y), (x + size, y + size), (x, y + size))):
                    points[4 * tag + k] = corner
    else:
        raise BenchError(f"{path}: target_type '{kind}' is neither checkerboard nor aprilgrid")
    _check_against_module(path, points)
    return kind, points


def _check_against_module(path, points):
    """Where omnical's Python module imports, its Target must number the corners the same."""
    try:
        import omnical
    except ImportError:
        return
    ids, board = omnical.Target.load(path).points()
    theirs = {int(i): (float(p[0]), float(p[1])) for i, p in zip(ids, board)}
    if set(theirs) != set(points) or any(max(abs(theirs[i][0] - x), abs(theirs[i][1] - y)) > 1e-9
                                         for i, (x, y) in points.items()):
        raise BenchError(f"{path}: corner ids map to other board points than omnical.Target's")


class Board:
    """The target's corners on mrcal's regular grid: mrcal boards are W x H points at one
    spacing, so the spacing is the largest that divides every coordinate (a checkerboard's
    square; for an aprilgrid the gcd of tag size and pitch, the rest of the grid unobserved)."""

    def __init__(self, spec_path):
        self.kind, self.points_mm = board_points_mm(spec_path)
        micrometres = [int(round(1000.0 * v)) for p in self.points_mm.values() for v in p]
        step = 0
        for value in micrometres:
            step = math.gcd(step, abs(value))
        if step == 0:
            raise BenchError(f"{spec_path}: all corners at the origin")
        self.spacing_mm = step / 1000.0
        self.cell = {i: (int(round(p[1] / self.spacing_mm)), int(round(p[0] / self.spacing_mm)))
                     for i, p in self.points_mm.items()}
        if min(min(c) for c in self.cell.values()) < 0:
            raise BenchError(f"{spec_path}: corners at negative board coordinates")
        self.height = 1 + max(c[0] for c in self.cell.values())
        self.width = 1 + max(c[1] for c in self.cell.values())
        if self.width * self.height > 40000:
            raise BenchError(f"{spec_path}: the common grid of the corners is {self.width} x {self.height}: too fine for mrcal")

    def observations(self, views):
        """mrcal's observations_board (views, H, W, 3): x, y, weight 1; -1 where no corner."""
        grid = np.full((len(views), self.height, self.width, 3), -1.0)
        for v, view in enumerate(views):
            for corner_id, pixel in zip(view["ids"], view["pixels"]):
                if corner_id not in self.cell:
                    raise BenchError(f"corner id {corner_id} is not on the target")
                row, col = self.cell[corner_id]
                grid[v, row, col] = (pixel[0], pixel[1], 1.0)
        return grid


# ---------------------------------------------------------------------------- detections

def read_json(path):
    try:
        with open(path) as handle:
            return json.load(handle)
    except OSError as error:
        raise BenchError(f"{path}: {error.strerror}")
    except json.JSONDecodeError as error:
        raise BenchError(f"{path}: not JSON ({error.msg}, line {error.lineno})")


def read_detections(path):
    """The corners omnical fits: per image its ids and pixels, without the corners whose
    refinement failed ("refined": false; calibrate leaves those out)."""
    data = read_json(path)
    try:
        views = []
        for image in data["images"]:
            kept = [c for c in image["corners"] if c.get("refined", True)]
            views.append(dict(image=image["image"], ids=[int(c["id"]) for c in kept],
                              pixels=np.array([c["pixel"] for c in kept], dtype=float).reshape(-1, 2)))
        return data, tuple(int(v) for v in data["image_size"]), views
    except (KeyError, TypeError, ValueError) as error:
        raise BenchError(f"{path}: unexpected detections layout ({error})")


def write_detections(data, names, path):
    """A detections.json holding only the images in `names` (for subset fits)."""
    subset = dict(data)
    subset["images"] = [image for image in data["images"] if image["image"] in names]
    with open(path, "w") as handle:
        json.dump(subset, handle)


# ---------------------------------------------------------------------------- the CLI

class Omnical:
    def __init__(self, binary, wait_s=120):
        self.binary = os.path.abspath(binary)
        self.wait_s = wait_s
        self._wait_for_binary()
        calibrate_help = self._help(["calibrate", "--help"])
        top_help = self._help(["--help"])
        self.has_holdout = "--holdout" in calibrate_help
        self.has_board_warp = "--board-warp" in calibrate_help
        self.has_cross_validate = "--cross-validate" in calibrate_help
        self.has_cross_validate_distance = "--cross-validate-distance-mm" in calibrate_help
        self.has_diff = re.search(r"^\s+diff\s", top_help, re.M) is not None

    def _wait_for_binary(self):
        # A build tree's binary is relinked from time to time: wait for it rather than fail
        # (not when its directory does not exist either).
        deadline = time.time() + self.wait_s
        while not os.access(self.binary, os.X_OK):
            if time.time() > deadline or not os.path.isdir(os.path.dirname(self.binary)):
                raise BenchError(f"{self.binary}: no such executable")
            time.sleep(5)

    def _help(self, args):
        return self._run(args, check=False).stdout

    def _run(self, args, check=True):
        for attempt in range(2):
            self._wait_for_binary()
            try:
                result = subprocess.run([self.binary] + args, capture_output=True, text=True)
            except OSError:
                if attempt == 0:  # replaced while we started it: wait and retry once
                    time.sleep(10)
                    continue
                raise BenchError(f"{self.binary}: cannot run")
            if result.returncode in (126, 127) and attempt == 0:
                time.sleep(10)
                continue
            break
        if check and result.returncode != 0:
            lines = [line for line in result.stderr.splitlines() if line.strip()]
            last = lines[-1] if lines else f"exit {result.returncode}"
            command = next(a for a in args if not a.startswith("-"))
            raise BenchError(f"{self.binary} {command} failed (exit {result.returncode}): {last}")
        return result

    def calibrate(self, target, out_dir, images=None, detections=None, guess=None, extra=()):
        args = ["--quiet", "calibrate", "--target", target, "--out", out_dir]
        args += ["--images", images] if images else ["--detections", detections]
        if guess:
            args += ["--sensor", guess]
        start = time.perf_counter()
        self._run(args + list(extra))
        seconds = time.perf_counter() - start
        calibration = read_json(os.path.join(out_dir, "calibration.json"))
        calibration["_seconds"] = seconds
        calibration["_dir"] = out_dir
        return calibration

    def diff(self, a, b, distance_mm, field, out_dir):
        """`omnical diff A B --distance-mm D --field detections.json --out DIR` -> diff.json."""
        self._run(["--quiet", "diff", a, b, "--distance-mm", f"{distance_mm:g}", "--field", field, "--out", out_dir])
        path = os.path.join(out_dir, "diff.json")
        result = read_json(path)
        try:
            return dict(diff_rms_px=float(result["diff_rms_px"]), diff_max_px=float(result["diff_max_px"]))
        except (KeyError, TypeError, ValueError):
            raise BenchError(f"{path}: no diff_rms_px / diff_max_px")


# ---------------------------------------------------------------------------- residuals

def _rotation_wxyz(q):
    w, x, y, z = np.asarray(q, dtype=float) / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def _project(omnical_cli, sensor_path, points_mm):
    """Pixels (N, 2) of camera-frame points through a sensor file, NaN where it fails:
    the Python module when it imports, else `omnical project`."""
    try:
        import omnical
        sensor = omnical.Sensor.load(sensor_path)
        pixels, status = sensor.project(np.ascontiguousarray(points_mm))
        pixels = np.array(pixels, dtype=float)
        pixels[status != omnical.ProjectionStatus.OK] = np.nan
        return pixels
    except ImportError:
        pass
    with tempfile.TemporaryDirectory() as scratch:
        points = os.path.join(scratch, "points.csv")
        np.savetxt(points, points_mm, delimiter=",", fmt="%.17g")
        out = omnical_cli._run(["project", "--sensor", sensor_path, "--points", points]).stdout.splitlines()[1:]
    pixels = np.full((len(points_mm), 2), np.nan)
    for i, line in enumerate(out):
        u, v, status = line.split(",")
        if status.strip() == "ok":
            pixels[i] = (float(u), float(v))
    return pixels


def board_warp_offsets_mm(calibration, board, ids):
    """Out-of-plane offsets (mm) of the corners `ids` under the fit's board warp
    (calibration.json "board_warp", calib/board_warp.h): z = x_mm (1 - u^2) + y_mm (1 - v^2),
    u, v the corner scaled to [-1, 1] over the extent of all the board's corners, plus each
    corner's own relief where one was fitted ("relief": id, offset_mm); 0 without one."""
    warp = calibration.get("board_warp")
    if not warp:
        return np.zeros(len(ids))
    points = np.array(list(board.points_mm.values()), dtype=float)
    low, high = points.min(axis=0), points.max(axis=0)
    span = np.where(high > low, high - low, 1.0)
    xy = np.array([board.points_mm[i] for i in ids], dtype=float)
    uv = 2.0 * (xy - low) / span - 1.0
    basis = np.where(high > low, 1.0 - uv ** 2, 0.0)
    relief = {int(c["id"]): float(c["offset_mm"]) for c in warp.get("relief", [])}
    return basis @ np.array([float(warp["x_mm"]), float(warp["y_mm"])]) + np.array([relief.get(i, 0.0) for i in ids])


def omnical_corner_residuals(omnical_cli, calibration, board, views):
    """Per-corner projection - observation (px, (N, 2), NaN where a point does not project) of
    every corner of the views the fit used, through the written sensor.yaml, the fitted poses
    (calibration.json "poses") and the fitted board warp; per row its view index, observed
    pixel and board point (mm)."""
    sensor = os.path.join(calibration["_dir"], "sensor.yaml")
    residuals, view_of, observed, board_xy = [], [], [], []
    for index, view in enumerate(views):
        pose = calibration["poses"].get(view["image"])
        if pose is None:
            continue
        rotation = _rotation_wxyz(pose["camera_from_target_quaternion_wxyz"])
        translation = np.array(pose["camera_from_target_translation_mm"], dtype=float)
        offsets = board_warp_offsets_mm(calibration, board, view["ids"])
        board_mm = np.array([(*board.points_mm[i], z) for i, z in zip(view["ids"], offsets)])
        pixels = _project(omnical_cli, sensor, board_mm @ rotation.T + translation)
        residuals.append(pixels - view["pixels"])
        view_of += [index] * len(view["ids"])
        observed.append(view["pixels"])
        board_xy.append(board_mm[:, :2])
    if not residuals:
        return np.zeros((0, 2)), np.zeros(0, dtype=int), np.zeros((0, 2)), np.zeros((0, 2))
    return np.concatenate(residuals), np.array(view_of), np.concatenate(observed), np.concatenate(board_xy)
