#!/usr/bin/env python3
"""The realistic rendered sets re-rendered with other seeds, calibrated with each corner and
weighting option, scored against the truth (writes docs/realistic-seeds.md).

The bundled realistic sets are one draw each: one set of random board poses, one noise.
Whether an option (--checkerboard-subpixel, --view-weights, --detection-passes 3) helps, and whether the reported
std are honest, only shows over several draws. For each seed k the scene
datasets-synthetic/scenes/realistic-<kind>.yaml is rendered with its noise seed and its
random-pose seed both moved by k (the four fixed rim and inner-radius views stay), then
calibrated from the images exactly as tests/cli/realistic_render_test.sh does (through the
misaligned design guess, --board-warp), once per option set.

Per option set: the RMS over the seeds of each parameter's error from the truth (in the
sphere's tilt-0 gauge, tests/cli/sphere_truth.py), the RMS of error / reported std (1 when
the std are honest), how many seeds have a parameter beyond 3 std and the worst, and the
visible corners found and used by the fit (found, refined where asked, not cut).

Usage: tests/bench/realistic_seeds.py --omnical build/test/tools/omnical [--seeds 6]
       [--kinds checkerboard,aprilgrid] [--option-sets '(default);--view-weights'] [--out docs/realistic-seeds.md]
~1 min per seed and option set on 2 cores (render ~20 s per seed, each calibration ~20 s).
"""
import argparse
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import time

source_dir = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(source_dir, "tests", "cli"))
import sphere_truth  # noqa: E402

data_dir = os.path.join(source_dir, "datasets-synthetic")
targets = {"checkerboard": "checkerboard-8x6-30mm.yaml", "aprilgrid": "aprilgrid-6x6-30mm.yaml"}
option_sets = {
    "checkerboard": [[], ["--checkerboard-subpixel"], ["--view-weights"]],
    "aprilgrid": [[], ["--detection-passes", "3"], ["--view-weights"]],
}
parameter_names = ["fx_px", "fy_px", "cx_px", "cy_px", "k1", "k2", "A_mm", "decenter_x_mm", "decenter_y_mm", "m_mm"]


def seeded_scene(kind, k, path):
    """The bundled scene with both seeds moved by k and its relative paths made absolute."""
    text = open(os.path.join(data_dir, "scenes", "realistic-%s.yaml" % kind)).read()
    text = text.replace("../", data_dir + "/")
    text = re.sub(r"\bseed: (\d+)", lambda m: "seed: %d" % (int(m.group(1)) + 1000 * k), text)
    open(path, "w").write(text)


def run(command):
    done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        sys.exit("realistic_seeds: %s exited %d: %s" % (command[1:3], done.returncode, done.stderr.strip()[-400:]))


def score(render_dir, cal_dir):
    result = json.load(open(os.path.join(cal_dir, "calibration.json")))
    truth = sphere_truth.truth_parameters(os.path.join(render_dir, "sensor.yaml"))
    p = result["parameters"]
    errors = {n: p[n]["value"] - truth[n] for n in parameter_names if not p[n]["fixed"]}
    z = {n: errors[n] / p[n]["std"] for n in errors}
    visible, found, squares = sphere_truth.corner_counts(render_dir, os.path.join(cal_dir, "detections.json"))
    used = len(squares) - result["outliers"]
    return {"errors": errors, "z": z, "visible": visible, "found": found, "used": used,
            "views": len(result["poses"]), "corner_rms_px": math.sqrt(sum(squares) / len(squares))}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--omnical", required=True)
    parser.add_argument("--seeds", type=int, default=6)
    parser.add_argument("--kinds", default="checkerboard,aprilgrid")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--option-sets", default="",
                        help="only these option sets, ';'-separated as the report names them, e.g. '(default);--view-weights'")
    parser.add_argument("--out", default=os.path.join(source_dir, "docs", "realistic-seeds.md"))
    args = parser.parse_args()
    started = time.time()
    kinds = args.kinds.split(",")
    scores = {}  # (kind, options) -> [score per seed]
    with tempfile.TemporaryDirectory() as work:
        for kind in kinds:
            target = os.path.join(data_dir, "targets", targets[kind])
            guess = os.path.join(data_dir, "sensors", "ohte-sph-misaligned-guess.yaml")
            for k in range(1, args.seeds + 1):
                scene = os.path.join(work, "scene-%s-%d.yaml" % (kind, k))
                render_dir = os.path.join(work, "render-%s-%d" % (kind, k))
                seeded_scene(kind, k, scene)
                run([args.omnical, "-q", "render", "--scene", scene, "--out", render_dir, "--threads", str(args.threads)])
                for options in option_sets[kind]:
                    if args.option_sets and (" ".join(options) or "(default)") not in args.option_sets.split(";"):
                        continue
                    cal_dir = os.path.join(work, "cal-%s-%d-%s" % (kind, k, "".join(options) or "default"))
                    run([args.omnical, "-q", "calibrate", "--target", target, "--images", render_dir, "--sensor", guess,
                         "--board-warp", "--threads", str(args.threads)] + options + ["--out", cal_dir])
                    s = score(render_dir, cal_dir)
                    scores.setdefault((kind, " ".join(options) or "(default)"), []).append(s)
                    print("%s seed %d %-40s worst %.1f std, used %d of %d" % (
                        kind, k, " ".join(options) or "(default)", max(abs(v) for v in s["z"].values()), s["used"],
                        s["visible"]), file=sys.stderr, flush=True)
    write_report(args, kinds, scores, time.time() - started)


def write_report(args, kinds, scores, seconds):
    lines = ["# The realistic sets over other seeds", "",
             "Generated by `tests/bench/realistic_seeds.py`; do not edit. Regenerate with", "", "```sh",
             "python3 tests/bench/realistic_seeds.py --omnical build/test/tools/omnical --seeds %d" % args.seeds, "```", "",
             "Each seed k re-renders `datasets-synthetic/scenes/realistic-<kind>.yaml` with its noise and random-pose "
             "seeds moved by 1000 k (the rim and inner-radius views stay), then calibrates it from the images as "
             "`cli.realistic_render` does (`calibrate --images ... --sensor ohte-sph-misaligned-guess.yaml "
             "--board-warp`) with each option set. Errors are from the truth in the sphere's tilt-0 gauge; "
             "*error / std* is the RMS over seeds and parameters of each error over its reported std (1 when the "
             "std are honest); *beyond 3 std*: the seeds with any parameter beyond 3 reported std. Corners: "
             "visible in the truth, found by detection, used by the fit (refined where asked, not cut), summed over the "
             "seeds; corner RMS: the refined corners' px distance from the truth, per corner.", ""]
    for kind in kinds:
        lines += ["## %s, %d seeds" % (kind, args.seeds), ""]
        header = "| options | " + " | ".join(parameter_names) + " | error / std | beyond 3 std (worst) | found | used | corner RMS (px) |"
        lines += [header, "|" + " --- |" * (header.count("|") - 1)]
        for (k, options), per_seed in scores.items():
            if k != kind:
                continue
            rms = {n: math.sqrt(sum(s["errors"][n] ** 2 for s in per_seed if n in s["errors"]) / len(per_seed))
                   for n in parameter_names if all(n in s["errors"] for s in per_seed)}
            zs = [z for s in per_seed for z in s["z"].values()]
            worst = [max(abs(z) for z in s["z"].values()) for s in per_seed]
            visible = sum(s["visible"] for s in per_seed)
            found = sum(s["found"] for s in per_seed)
            used = sum(s["used"] for s in per_seed)
            corner = math.sqrt(sum(s["corner_rms_px"] ** 2 for s in per_seed) / len(per_seed))
            lines.append("| %s | %s | %.2f | %d of %d (%.1f) | %.2f %% | %.2f %% | %.3f |" % (
                options, " | ".join("%.3g" % rms[n] if n in rms else "fixed" for n in parameter_names),
                math.sqrt(sum(z * z for z in zs) / len(zs)), sum(w > 3.0 for w in worst), len(per_seed), max(worst),
                100.0 * found / visible, 100.0 * used / visible, corner))
        lines.append("")
        lines += ["Worst |error| / std per seed:", ""]
        for (k, options), per_seed in scores.items():
            if k == kind:
                lines.append("- %s: %s" % (options, ", ".join(
                    "%.1f (%s)" % max((abs(z), n) for n, z in s["z"].items()) for s in per_seed)))
        lines.append("")
    lines.append("Generated in %.0f s." % seconds)
    tmp = args.out + ".tmp"
    open(tmp, "w").write("\n".join(lines) + "\n")
    os.replace(tmp, args.out)


if __name__ == "__main__":
    main()
