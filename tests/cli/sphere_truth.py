"""The truth of a rendered spherical-mirror set as the fit sees it (for the CLI tests).

A sphere's tilt is its gauge (a sphere turned about its centre is the same surface), so
calibrate holds tilt at the design's 0 and the truth is compared through the sphere's
centre: decenter + Ry Rx (0, 0, A) laterally, m + A along the axis.
"""
import glob
import json
import math
import os
import re


def truth_parameters(sensor_yaml_path):
    """Parameters by calibration.json name from a render's sensor.yaml (flow-style YAML
    written by omnical; numbers read by regex), in the tilt-0 gauge."""
    text = open(sensor_yaml_path).read()

    def scalar(key):
        return float(re.search(r"\b" + key + r":\s*([-+0-9.eE]+)", text).group(1))

    def pair(key):
        return [float(x) for x in re.search(r"\b" + key + r":\s*\[([^\]]*)\]", text).group(1).split(",")]

    fx, fy, cx, cy, k1, k2, A, m = (scalar(k) for k in ("fx", "fy", "cx", "cy", "k1", "k2", "A", "m"))
    tx, ty = (math.radians(v) for v in pair("tilt_deg"))
    dx, dy = pair("decenter_mm")
    centre = (dx + A * math.cos(tx) * math.sin(ty), dy - A * math.sin(tx), m + A * math.cos(tx) * math.cos(ty))
    return {"fx_px": fx, "fy_px": fy, "cx_px": cx, "cy_px": cy, "k1": k1, "k2": k2, "A_mm": A,
            "decenter_x_mm": centre[0], "decenter_y_mm": centre[1], "m_mm": centre[2] - A}


def corner_counts(render_dir, detections_path):
    """Corners of a rendered set against its ground truth: (visible, found, squares), where
    visible counts the corners the truth files mark visible, found those of them that
    detections_path holds (refined or not), and squares lists the squared px distance from
    the truth of each found corner that was refined (what the fit is given)."""
    detections = json.load(open(detections_path))
    found = 0
    squares = []
    for view in detections["images"]:
        truth = {c["id"]: c for c in json.load(open(os.path.splitext(view["image"])[0] + ".json"))["targets"][0]["corners"]}
        seen = {c["id"] for c in view["corners"] if c["id"] in truth and truth[c["id"]]["visible"]}
        found += len(seen)
        squares += [math.dist(c["pixel"], truth[c["id"]]["pixel"]) ** 2
                    for c in view["corners"] if c["id"] in seen and c.get("refined", True)]
    visible = 0
    for path in glob.glob(os.path.join(render_dir, "*.json")):
        truth = json.load(open(path))
        if "targets" in truth:
            visible += sum(1 for c in truth["targets"][0]["corners"] if c["visible"])
    return visible, found, squares
