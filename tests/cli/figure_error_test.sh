#!/usr/bin/env bash
# A mirror no shipped formula matches, from the images alone (issue 20): the misaligned
# sphere with a 20 um zonal figure error (datasets-synthetic/sensors/ohte-sph-figure-error.*,
# scripts/figure-error-table.py), 24 rendered views of a 50 mm-tag aprilgrid at 3-45 mirror
# radii, calibrated from the sphere's design guess with the spline profile and its knot
# count chosen by held-out folds, the lens's focal length held at the design value (0.1 %
# off the truth; a user knows the lens: with a free-form mirror the focal length and m
# trade off, docs/calibrate.md). Checked:
#  - a spline is chosen, and the sphere it replaces predicts held-out views > 2x worse;
#  - the fit reaches the noise floor: its RMS over all corners within 10 % of the detected
#    corners' RMS distance from the render's ground truth (both per corner);
#  - it projects like the true mirror over the observed field at n = 2, 7 and infinity
#    mirror radii (`omnical diff` against the truth, after the best rigid alignment): RMS
#    < 0.1 px at each.
# The fallback when the folds' count fits the full set to no valid mirror is tested apart,
# deterministically (KnotChoice.AFullFitThatIsNoValidMirrorIsReplacedByTheNextPreferredCount):
# here it happened or not by the last digits of a focal-free fit.
# Usage: figure_error_test.sh OMNICAL_BINARY SOURCE_DIR
set -u
omnical=$1
source_dir=$(cd "$2" && pwd)
data=$source_dir/datasets-synthetic
source "$(dirname "${BASH_SOURCE[0]}")/harness.sh"

"$omnical" -q render --scene "$data/scenes/ohte-sph-figure-error.yaml" --out "$work/render" || { echo "FAIL: render"; exit 1; }
"$omnical" -q calibrate --target "$data/targets/aprilgrid-6x6-50mm.yaml" --images "$work/render" \
  --sensor "$data/sensors/ohte-sph-misaligned-guess.yaml" --profile spline --knots auto --fix lens_scale \
  --out "$work/cal" 2>"$work/calibrate.err" || { rc=$?; cat "$work/calibrate.err"; echo "FAIL: calibrate exited $rc"; exit 1; }
grep -h "knot" "$work/calibrate.err"  # the fallback's warning, should it happen

python3 - "$work/render" "$work/cal" "$work/cal/detections.json" <<'PY' && pass || fail "spline fit of the figure-error sphere"
import glob, json, math, os, sys
render, cal = sys.argv[1], sys.argv[2]  # argv[3]: the detected corners
result = json.load(open(os.path.join(cal, "calibration.json")))
choice = result["knot_choice"]
scores = dict(zip(choice["candidates"], choice["held_out_rms_px"]))
print("knots chosen: %d; held-out RMS by count (0: sphere): %s" %
      (choice["chosen"], ", ".join("%d: %.4f" % kv for kv in scores.items())))
ok = result["converged"] and choice["chosen"] > 0 and scores[0] > 2.0 * scores[choice["chosen"]]
# The render's corner noise: refined detected corners against the ground truth.
det = json.load(open(sys.argv[3]))
square, count = 0.0, 0
for view in det["images"]:
    truth = json.load(open(os.path.splitext(view["image"])[0] + ".json"))
    pixels = {c["id"]: c["pixel"] for c in truth["targets"][0]["corners"] if c["visible"]}
    for c in view["corners"]:
        if c["id"] in pixels and c.get("refined", True):
            square += (c["pixel"][0] - pixels[c["id"]][0]) ** 2 + (c["pixel"][1] - pixels[c["id"]][1]) ** 2
            count += 1
noise = math.sqrt(square / count)
ratio = result["rms_all_px"] / noise
print("fit RMS %.4f px over all %d corners (%.4f without the %d outliers); detected corners %.4f px from the truth: "
      "ratio %.3f" % (result["rms_all_px"], result["observations"], result["rms_px"], result["outliers"], noise, ratio))
ok = ok and abs(ratio - 1.0) < 0.1
sys.exit(0 if ok else 1)
PY

rim_mm=43.9
for n in 2 7 inf; do
  distance=$([ "$n" = inf ] && echo 1e8 || awk -v n="$n" -v r="$rim_mm" 'BEGIN { print n * r }')
  if "$omnical" diff "$work/cal" "$work/render/sensor.yaml" --field "$work/cal/detections.json" --distance-mm "$distance" \
    >"$work/diff_$n.txt"; then
    cat "$work/diff_$n.txt"
    rms=$(sed -n 's/.*: RMS \([0-9.]*\) px, median.*/\1/p' "$work/diff_$n.txt")
    grep -q "^alignment: fitted" "$work/diff_$n.txt" && awk -v e="$rms" 'BEGIN { exit !(e != "" && e + 0 < 0.1) }' && pass ||
      fail "n = $n: projection RMS '$rms' px from the true mirror over the observed field (bound 0.1)"
  else
    fail "diff at n = $n exited $?"
  fi
done
summary figure_error_test
