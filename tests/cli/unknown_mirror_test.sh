#!/usr/bin/env bash
# A new user's first calibration: a sensor none of the bundled guesses describes (a
# hyperboloid behind a 4:3 camera of 800 x 600 px, tilted and decentred:
# datasets-synthetic/sensors/hyperboloid-800x600.yaml), hand-held paper checkerboard views
# as messy as realistic-checkerboard's (bent by 3 / 1 mm, blur, noise, colour JPEG 85,
# boards by the rim and the inner radius), calibrated from the images alone with no option
# but the target: the defaults must choose the lens by held-out folds and fit the board's
# warp. Rendered here (scenes/realistic-hyperboloid.yaml, ~10 s on 2 cores).
# Measured (2026-11-29): the corners of 14 views, 666 of the 668 the truth sees, used;
# RMS 0.071 px; the warp 3.007 +- 0.045 / 0.984 +- 0.042 mm; the lens choice keeps the
# orthographic (held out 0.105 px against the pinhole's 0.128), and the mirror family
# choice the polynomial (the even asphere 0.112 px; measured 2026-11-30); against the true sensor,
# after the best rigid alignment over the detected field, 0.065 px RMS at 300 mm and
# 0.084 px at 2 m. The same corners with the board held flat (--no-board-warp; the default
# before, which also refined the corners through a flat fit): 0.159 px RMS, 0.165 / 0.200 px
# from the truth: the mirror bent for the paper. Bounds: the warp
# within 10 % (the issue's), 0.12 px from the truth at both distances, 99 % of the visible
# corners used, and the flat fit at least 1.5 times as far from the truth.
# Usage: unknown_mirror_test.sh OMNICAL_BINARY SOURCE_DIR
set -u
omnical=$1
source_dir=$(cd "$2" && pwd)
data=$source_dir/datasets-synthetic
source "$source_dir/tests/cli/harness.sh"
target=$data/targets/checkerboard-8x6-30mm.yaml

"$omnical" -q render --scene "$data/scenes/realistic-hyperboloid.yaml" --out "$work/render" ||
  { echo "FAIL: render exited $?"; exit 1; }
"$omnical" -q calibrate --target "$target" --images "$work/render" --out "$work/cal" 2>/dev/null ||
  { echo "FAIL: calibrate exited $?"; exit 1; }
"$omnical" -q calibrate --target "$target" --detections "$work/cal/detections.json" --no-board-warp \
  --out "$work/flat" 2>/dev/null || { echo "FAIL: calibrate --no-board-warp exited $?"; exit 1; }
for cal in cal flat; do
  for mm in 300 2000; do
    "$omnical" -q diff "$work/render/sensor.yaml" "$work/$cal" --distance-mm "$mm" --field "$work/cal/detections.json" \
      --out "$work/diff_${cal}_$mm" >/dev/null || fail "diff $cal at $mm mm exited $?"
  done
done
python3 - "$work" <<'PY' && pass || fail "unknown mirror from the images alone"
import glob, json, os, sys
work = sys.argv[1]
cal = json.load(open(work + "/cal/calibration.json"))
flat = json.load(open(work + "/flat/calibration.json"))
diff = {(c, mm): json.load(open("%s/diff_%s_%d/diff.json" % (work, c, mm)))["diff_rms_px"]
        for c in ("cal", "flat") for mm in (300, 2000)}
print("RMS %.3f px (flat %.3f); from the truth %.3f / %.3f px at 300 / 2000 mm (flat %.3f / %.3f)" % (
    cal["rms_px"], flat["rms_px"], diff["cal", 300], diff["cal", 2000], diff["flat", 300], diff["flat", 2000]))
lens = cal["lens_choice"]  # scored (the orthographic at least), and the lens written the one chosen
assert lens["folds"] == 5 and lens["held_out_rms_px"][0] is not None and lens["held_out_rms_px"][0] > 0, lens
assert ("model: " + lens["chosen"]) in open(work + "/cal/sensor.yaml").read(), lens
assert "(chosen by held-out folds)" in cal["start"], cal["start"]
profile = cal["profile_choice"]  # scored both ways, and the family written the one chosen
print("held out: polynomial %s, even asphere %s px" % tuple(profile["held_out_rms_px"]))
assert None not in profile["held_out_rms_px"] and profile["held_out_corners"] == lens["held_out_corners"], profile
assert ("profile: " + profile["chosen"]) in open(work + "/cal/sensor.yaml").read(), profile
warp = cal["board_warp"]
print("warp %.3f +- %.3f, %.3f +- %.3f mm" % (warp["x_mm"], warp["std_x_mm"], warp["y_mm"], warp["std_y_mm"]))
assert abs(warp["x_mm"] - 3.0) < 0.3 and abs(warp["y_mm"] - 1.0) < 0.1, warp
assert "board_warp" not in flat, flat.get("board_warp")
for mm in (300, 2000):
    assert diff["cal", mm] < 0.12, diff
    assert diff["flat", mm] > 1.5 * diff["cal", mm], diff
visible = 0
for truth in glob.glob(work + "/render/*.json"):
    view = json.load(open(truth))
    if "targets" in view:
        visible += sum(1 for c in view["targets"][0]["corners"] if c["visible"])
used = cal["observations"] - cal["outliers"]
print("corners used %d of %d visible" % (used, visible))
assert "views_left_out" not in cal and len(cal["poses"]) == 14, (cal.get("views_left_out"), len(cal["poses"]))
assert used >= 0.99 * visible, (used, visible)
PY
summary unknown_mirror_test
