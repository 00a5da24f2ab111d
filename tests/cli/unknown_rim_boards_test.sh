#!/usr/bin/env bash
# Boards by the rim of an unknown mirror, from the images alone with no option but the
# target: datasets-synthetic/rendered/realistic-checkerboard (a sphere behind a pinhole;
# bent paper boards, blur, noise, colour JPEG 85; two boards by the rim, rim0 and rim1, and
# real007 beyond the other boards' reach). The first detection pass misses those three; the
# second finds them only through a first fit that extrapolates to the images' rim circle.
# The mirror family is chosen by held-out folds (calib/profile_choice.h): the even asphere
# (a conic) predicts the held-out views at 0.202 px against the polynomial's 0.210
# (measured 2026-11-30); its first fit puts the rim circle 10.1 % beyond its corners, which
# a conic may follow (calib/rim_circle.h), and all 12 views are used. The boards pass 2
# finds were refined through a fit that had not seen them, so a third pass follows: all
# 570 corners the truth sees used (553 without it, the rim boards' corners bending the fit
# into the dolly-zoom valley, 0.069 / 0.31 px from the truth at 300 mm / 2 m), RMS 0.040
# px, the warp 2.985 / 0.973 mm, and 0.013 / 0.030 px from the true sensor at 300 mm / 2 m
# after the best rigid alignment over the detected field. Before (the polynomial alone): 9
# views, 418 corners, rim0, rim1 and real007 skipped, 0.116 / 0.140 px from the truth over
# its narrower field; widened to the circle anyway, the polynomial's refit fell to 6.2 px.
# Bounds: every view used and none skipped, 99 % of the visible corners (the issue's),
# 0.05 / 0.1 px from the truth (4 / 3 x the measured: a fit missing the third pass fails
# both), the even asphere chosen on a margin over 1 % (the choice rule's).
# Usage: unknown_rim_boards_test.sh OMNICAL_BINARY SOURCE_DIR
set -u
omnical=$1
source_dir=$(cd "$2" && pwd)
data=$source_dir/datasets-synthetic
source "$source_dir/tests/cli/harness.sh"
set_dir=$data/rendered/realistic-checkerboard

"$omnical" -q calibrate --target "$data/targets/checkerboard-8x6-30mm.yaml" --images "$set_dir" --threads 2 \
  --out "$work/cal" 2>/dev/null || { echo "FAIL: calibrate exited $?"; exit 1; }
# And at the boards' median distance, where the calibration predicts its own error.
median_mm=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['predicted_error'][0]['distance_mm'])" \
  "$work/cal/calibration.json") || fail "no predicted error"
for mm in 300 2000 "$median_mm"; do
  "$omnical" -q diff "$set_dir/sensor.yaml" "$work/cal" --distance-mm $mm --field "$work/cal/detections.json" \
    --out "$work/diff_$mm" >/dev/null || fail "diff at $mm mm exited $?"
done
python3 - "$work" "$set_dir" "$median_mm" <<'PY' && pass || fail "rim boards of an unknown mirror from the images alone"
import glob, json, sys
work, set_dir = sys.argv[1:3]
cal = json.load(open(work + "/cal/calibration.json"))
diff = {mm: json.load(open("%s/diff_%d/diff.json" % (work, mm))) for mm in (300, 2000)}
profile = cal["profile_choice"]
polynomial, conic = profile["held_out_rms_px"]
print("held out: polynomial %.4f, even asphere %.4f px; chosen %s" % (polynomial, conic, profile["chosen"]))
assert profile["chosen"] == "even_asphere" and conic < 0.99 * polynomial, profile
assert "profile: even_asphere" in open(work + "/cal/sensor.yaml").read()
visible = sum(sum(1 for c in json.load(open(f))["targets"][0]["corners"] if c["visible"])
              for f in glob.glob(set_dir + "/*.json") if "targets" in json.load(open(f)))
used = cal["observations"] - cal["outliers"]
print("views %d, corners used %d of %d visible; RMS %.4f px; from the truth %.4f / %.4f px at 300 / 2000 mm" % (
    len(cal["poses"]), used, visible, cal["rms_px"], diff[300]["diff_rms_px"], diff[2000]["diff_rms_px"]))
assert len(cal["poses"]) == 12 and "views_skipped" not in cal and "views_left_out" not in cal, (
    len(cal["poses"]), cal.get("views_skipped"), cal.get("views_left_out"))
assert not any("fit's own rim" in w for w in cal.get("warnings", [])), cal["warnings"]
assert cal["detection_passes"] == 3, cal["detection_passes"]
assert used >= 0.99 * visible, (used, visible)
assert diff[300]["aligned"] and diff[300]["diff_rms_px"] < 0.05 and diff[2000]["diff_rms_px"] < 0.1, diff
# The predicted error at the boards' median distance covers the actual one (3 sigma) and
# does not warn: 0.089 px predicted against 0.041 px actual (worst pixels; measured
# 2026-11-29). Taken in the camera's frame it read 1.98 px and warned.
predicted = cal["predicted_error"][0]
actual = json.load(open("%s/diff_%s/diff.json" % (work, sys.argv[3])))["diff_max_px"]
print("at %.0f mm: predicted worst %.3f px, actual %.3f px" % (predicted["distance_mm"], predicted["max_px"], actual))
assert actual <= 3 * predicted["max_px"] and predicted["max_px"] < 0.3, (predicted, actual)
# Every parameter within 3 reported std of the render's true sphere (the issue's), read
# from its sensor.yaml: a sphere of radius A is a conic of vertex radius A and k = 0.
# Measured: worst R, 1.66 std (49.590 +- 0.222 mm vs 49.958); the tilt and decenter are
# a sphere's gauge (stds of 5-35 deg, 4-30 mm) and pass trivially.
import re
text = open(set_dir + "/sensor.yaml").read()
number = lambda key: float(re.search(r"\b%s: ([-0-9.e]+)" % key, text).group(1))
pair = lambda key: [float(v) for v in re.search(r"%s: \[([^]]*)\]" % key, text).group(1).split(",")]
truth = {"fx_px": number("fx"), "fy_px": number("fy"), "cx_px": number("cx"), "cy_px": number("cy"), "k1": 0.0,
         "k2": 0.0, "m_mm": number("m"), "R_mm": number("A"), "k": 0.0, "tilt_x_deg": pair("tilt_deg")[0],
         "tilt_y_deg": pair("tilt_deg")[1], "decenter_x_mm": pair("decenter_mm")[0],
         "decenter_y_mm": pair("decenter_mm")[1]}
assert number("k1") == 0.0 and number("k2") == 0.0, text
deviation = {name: abs(cal["parameters"][name]["value"] - value) / cal["parameters"][name]["std"]
             for name, value in truth.items()}
print("parameters from the truth, in std: " + ", ".join("%s %.2f" % item for item in sorted(deviation.items())))
assert max(deviation.values()) < 3.0, deviation
PY
summary unknown_rim_boards_test
