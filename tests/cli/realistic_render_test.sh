#!/usr/bin/env bash
# The realistic rendered sets (datasets-synthetic/rendered/realistic-aprilgrid and
# realistic-checkerboard: a paper board bent by 3 mm along x and -1.5 / 1 mm along y,
# blur, noise, vignetting, colour, JPEG 85, boards near the rim and the inner radius),
# calibrated from their images through the design guess with the board's warp and the
# lens distortion fitted (the truth has none). The issue's bounds: the warp within 10 %,
# every fitted parameter within 3 reported std of the truth (in the sphere's tilt gauge,
# sphere_truth.py), no view left out. Measured: aprilgrid within 0.8 std (1.7 before each
# complete tag was fitted whole, calib/tag_template_fit.h), checkerboard
# within 2.2 std (fx, m and k2 4.7-4.8 std off before calib/checkerboard_candidates.h's
# junction check put real001's sheared corners back on their junctions; fx, k2 and
# decenter_x 3.2-4.8 std off when the corners were refined through the design guess
# instead of the first fit; inner1, the bent board at the inner radius, was refused as
# 0.66 x its size until calib/board_scale.h's ratio went from 1.5 to 1.65). Detection:
# corners found and corners used by the fit (found, refined where that is asked, not cut as
# outliers) above regression floors: aprilgrid found 98.5 % (measured 1675 of 1692:
# 98.99 %), used 98.3 % (1669: 98.6 %; 5 found corners left out unrefined, 1 cut; with
# the edge profiles alone 1631, 96.4 %: 44 rim corners unrefined), its corners within 0.1
# px RMS of the truth (0.051; 0.203 with the edge profiles alone); checkerboard found 97 %
# (557 of 570: 97.7 %; 13 rim corners not found), used 97 % (554: 97.2 %; 3 cut), within
# 0.3 px. Short of the 99 % wanted.
# checkerboard-edges: the checkerboard set with --checkerboard-edges (every corner refined by
# its edges through the first fit, calib/refine_corners.h, and the corners a fitted board
# lacks predicted through that fit and kept where a junction is found there,
# calib/checkerboard_completion.h): measured within 2.1 std (k1; fx 0.9), found 562 of 570
# (98.6 %: 5 of them predicted, 0.03-0.05 px from the truth; of the 8 left 7 are rim
# junctions whose outer side the rim cuts, one lies beyond the fitted rim), used 561
# (98.4 %), refined corners 0.065 px RMS from the truth (0.116 without): bounded at 0.1 px.
# Usage: realistic_render_test.sh OMNICAL_BINARY SOURCE_DIR [aprilgrid|checkerboard|checkerboard-edges]
set -u
omnical=$1
source_dir=$(cd "$2" && pwd)
kind=${3:-aprilgrid}
data=$source_dir/datasets-synthetic
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
extra=() corner_bound=0.3 predicted_floor=0
case $kind in
  aprilgrid) target=$data/targets/aprilgrid-6x6-30mm.yaml found_floor=0.985 used_floor=0.983 corner_bound=0.1 ;;
  checkerboard) target=$data/targets/checkerboard-8x6-30mm.yaml found_floor=0.97 used_floor=0.97 ;;
  checkerboard-edges) target=$data/targets/checkerboard-8x6-30mm.yaml found_floor=0.979 used_floor=0.978
    kind=checkerboard extra=(--checkerboard-edges) corner_bound=0.1 predicted_floor=4 ;;
  *) echo "FAIL: unknown set kind '$kind'"; exit 1 ;;
esac
set_dir=$data/rendered/realistic-$kind

"$omnical" -q calibrate --target "$target" --images "$set_dir" \
  --sensor "$data/sensors/ohte-sph-misaligned-guess.yaml" --board-warp --threads 2 "${extra[@]}" --out "$work/cal" 2>/dev/null ||
  { echo "FAIL: calibrate exited $?"; exit 1; }

OMNICAL_CLI_TESTS=$source_dir/tests/cli python3 - "$set_dir" "$work/cal" "$found_floor" "$used_floor" "$corner_bound" "$predicted_floor" <<'PY'
import glob, json, math, os, sys
sys.path.insert(0, os.environ["OMNICAL_CLI_TESTS"])
import sphere_truth
render, cal, found_floor, used_floor, corner_bound = sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
predicted_floor = int(sys.argv[6])
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
check(len(predicted_errors) >= predicted_floor and all(e < 0.1 for e in predicted_errors),
      "%d corners predicted through the first fit and confirmed (floor %d), each on a visible corner within 0.1 px of "
      "the truth (worst %.3f)" % (len(predicted_errors), predicted_floor, max(predicted_errors, default=0.0)))
check(rms < corner_bound, "refined corners %.3f px RMS from the ground truth (< %g)" % (rms, corner_bound))
sys.exit(1 if failed else 0)
PY
