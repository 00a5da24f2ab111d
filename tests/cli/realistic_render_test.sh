#!/usr/bin/env bash
# The realistic rendered sets (datasets-synthetic/rendered/realistic-aprilgrid and
# realistic-checkerboard: a paper board bent by 3 mm along x and -1.5 / 1 mm along y,
# blur, noise, vignetting, colour, JPEG 85, boards near the rim and the inner radius),
# calibrated from their images through the design guess with the board's warp and the
# lens distortion fitted (the truth has none). The issue's bounds: the warp within 10 %,
# every fitted parameter within 3 reported std of the truth (in the sphere's tilt gauge,
# sphere_truth.py), no view left out. Measured: aprilgrid within 1.4 std (A; 1.2 before rim
# corners were kept by the rim their tag's fit placed, 1.7 before each
# complete tag was fitted whole, calib/tag_template_fit.h), checkerboard
# within 2.2 std (k1; corners by their edges, the default; with cornerSubPix,
# --checkerboard-subpixel, 1.6 std, 2.2 before its rim junctions were predicted and fitted whole; fx, m and k2 4.7-4.8 std off before calib/checkerboard_candidates.h's
# junction check put real001's sheared corners back on their junctions; fx, k2 and
# decenter_x 3.2-4.8 std off when the corners were refined through the design guess
# instead of the first fit; inner1, the bent board at the inner radius, was refused as
# 0.66 x its size until calib/board_scale.h's ratio went from 1.5 to 1.65). Detection:
# corners found and corners used by the fit (found, refined where that is asked, not cut as
# outliers) above the issue's 99 %. The later detection passes see through the previous fit
# with its rim radius moved onto the images' rim circle (calib/rim_circle.h; the fit's own
# rim was the design's, 7-12 px off the image's at a first fit). Aprilgrid: found 1685 of
# 1692 (99.6 %), used 1685 (99.6 %; 1687 before the rim moved: rim tags fitted across a rim
# that was off by luck in their favour, one on a corner the truth does not see; over 6 other
# seeds the move took used 98.23 -> 98.57 % and fx's error 14.4 -> 8.0 px RMS,
# tests/bench/realistic_seeds.py; 1677 before rim corners were kept by the rim their tag's
# fit placed, 1 px inside it, and detector corners could move 1.25 cells), corners within
# 0.1 px RMS of the truth (0.047), 13 predicted at the rim and confirmed by the tag's fit
# across it (floor 8; worst 0.156 px, bound 0.2). Checkerboard: the corners a fitted board lacks are predicted through the first
# fit and kept where a junction is found there (calib/checkerboard_completion.h: by the edge
# profiles where they are clear of the rim, else by its squares fitted whole with the rim
# modelled, calib/checker_junction_fit.h); found 570 of 570, 13 of them predicted, used 570
# (100 %; 0 cut; 567 and 3 cut with cornerSubPix), refined corners 0.041 px RMS from the
# truth (0.063 before the edges were kept clear of the rim; 0.116 with cornerSubPix):
# bounded at 0.06 px. Predicted corners confirmed: 0.01-0.23 px from the truth, the worst a junction 0.75 px
# inside the rim, bounded at 0.25 px (edge profiles read the black beyond the rim as ink: a
# junction 4.5 px inside it went 2.6 px off until they were kept clear of it).
# KEEP_DIR (optional): the calibration is also copied there, whatever the checks say (the
# decoy test compares against it: tests/cli/decoy_images_test.sh; under CTest it is not run
# when this test fails, its fixture's setup).
# Usage: realistic_render_test.sh OMNICAL_BINARY SOURCE_DIR [aprilgrid|checkerboard] [KEEP_DIR]
set -u
omnical=$1
source_dir=$(cd "$2" && pwd)
kind=${3:-aprilgrid}
keep=${4:-}
data=$source_dir/datasets-synthetic
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
corner_bound=0.3 predicted_floor=0 predicted_bound=0.25
case $kind in
  aprilgrid) target=$data/targets/aprilgrid-6x6-30mm.yaml found_floor=0.99 used_floor=0.99 corner_bound=0.1 predicted_floor=8
    predicted_bound=0.2 ;;
  checkerboard) target=$data/targets/checkerboard-8x6-30mm.yaml found_floor=0.99 used_floor=0.99 corner_bound=0.06
    predicted_floor=10 ;;
  *) echo "FAIL: unknown set kind '$kind'"; exit 1 ;;
esac
set_dir=$data/rendered/realistic-$kind
[ -z "$keep" ] || rm -rf "$keep"  # never an earlier run's, should this one fail

"$omnical" -q calibrate --target "$target" --images "$set_dir" \
  --sensor "$data/sensors/ohte-sph-misaligned-guess.yaml" --board-warp --threads 2 --out "$work/cal" 2>/dev/null ||
  { echo "FAIL: calibrate exited $?"; exit 1; }
if [ -n "$keep" ]; then
  rm -rf "$keep.tmp" "$keep" && cp -r "$work/cal" "$keep.tmp" && mv "$keep.tmp" "$keep" || { echo "FAIL: keeping the calibration in $keep"; exit 1; }
fi

OMNICAL_CLI_TESTS=$source_dir/tests/cli python3 - "$set_dir" "$work/cal" "$found_floor" "$used_floor" "$corner_bound" "$predicted_floor" "$predicted_bound" <<'PY'
import glob, json, math, os, sys
sys.path.insert(0, os.environ["OMNICAL_CLI_TESTS"])
import sphere_truth
render, cal, found_floor, used_floor, corner_bound = sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
predicted_floor, predicted_bound = int(sys.argv[6]), float(sys.argv[7])
failed = []
def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok: failed.append(what)

result = json.load(open(os.path.join(cal, "calibration.json")))
check(result["converged"], "converged")
truth_warp = json.load(open(os.path.join(render, "real000.json")))["targets"][0]["warp_mm"]
warp = result["board_warp"]
for axis, expected in zip("xy", truth_warp):
    value, std = warp[axis + "_mm"], warp["std_" + axis + "_mm"]
    check(abs(value - expected) <= 0.1 * abs(expected),
          "warp %s %.3f +- %.3f mm vs %.3f (within 10 %%; %.1f std)" % (axis, value, std, expected, (value - expected) / std))
p = result["parameters"]
for name, value in sphere_truth.truth_parameters(os.path.join(render, "sensor.yaml")).items():
    if not p[name]["fixed"]:
        z = (p[name]["value"] - value) / p[name]["std"]
        check(abs(z) <= 3.0, "%s %.5g +- %.3g vs truth %.5g: %.1f std (within 3)" % (name, p[name]["value"], p[name]["std"], value, z))
images = sorted(glob.glob(os.path.join(render, "*.jpg")))
check(len(result["poses"]) == len(images), "%d of %d views in the fit" % (len(result["poses"]), len(images)))
visible, found, squares = sphere_truth.corner_counts(render, os.path.join(cal, "detections.json"))
rms = math.sqrt(sum(squares) / len(squares))
used = len(squares) - result["outliers"]
check(found >= found_floor * visible, "found %d of %d visible corners (%.1f %%, floor %g %%; %d left out unrefined)" %
      (found, visible, 100.0 * found / visible, 100 * found_floor, found - len(squares)))
check(used >= used_floor * visible, "the fit used %d of %d visible corners (%.1f %%, floor %g %%; %d cut)" %
      (used, visible, 100.0 * used / visible, 100 * used_floor, result["outliers"]))
predicted_errors = []  # px from the truth; inf where the truth does not see the corner
for view in json.load(open(os.path.join(cal, "detections.json")))["images"]:
    truth = {c["id"]: c for c in json.load(open(os.path.splitext(view["image"])[0] + ".json"))["targets"][0]["corners"]}
    predicted_errors += [math.dist(c["pixel"], truth[c["id"]]["pixel"]) if truth[c["id"]]["visible"] else math.inf
                         for c in view["corners"] if c.get("predicted")]
check(len(predicted_errors) >= predicted_floor and all(e < predicted_bound for e in predicted_errors),
      "%d corners predicted through the first fit and confirmed (floor %d), each on a visible corner within %g px of "
      "the truth (worst %.3f)" % (len(predicted_errors), predicted_floor, predicted_bound, max(predicted_errors, default=0.0)))
check(rms < corner_bound, "refined corners %.3f px RMS from the ground truth (< %g)" % (rms, corner_bound))
sys.exit(1 if failed else 0)
PY
