#!/usr/bin/env bash
# End-to-end checks of the omnical command line: results of project/unproject, and the
# bad-input policy (exit code 2, exactly one line on stderr naming the file and field,
# no output file left behind).
# Usage: cli_test.sh OMNICAL_BINARY SOURCE_DIR CODECS_PLUGIN_OF_ANOTHER_BUILD CODECS_PLUGIN LIBDIR
set -u
omnical=$1
source_dir=$(cd "$2" && pwd)
other_build_plugin=$3
codecs_plugin=$4
libdir=$5
sensors=$source_dir/datasets-synthetic/sensors
source "$(dirname "${BASH_SOURCE[0]}")/harness.sh"

# expect_error NAME EXPECTED_SUBSTRING -- ARGS...: exit code 2, one stderr line containing
# the substring, and nothing at the --out path afterwards ($work/out.csv without one), nor a
# temporary file beside it.
expect_error() {
  local name=$1 expected=$2 out=$work/out.csv previous="" arg
  shift 3
  for arg in "$@"; do
    [ "$previous" = --out ] && out=$arg
    previous=$arg
  done
  rm -rf "$out"
  "$omnical" "$@" >"$work/stdout" 2>"$work/stderr"
  local code=$?
  local lines
  lines=$(wc -l <"$work/stderr")
  if [ "$code" -ne 2 ]; then fail "$name: exit code $code, expected 2"; return; fi
  if [ "$lines" -ne 1 ]; then fail "$name: $lines lines on stderr, expected 1: $(cat "$work/stderr")"; return; fi
  if ! grep -qF -- "$expected" "$work/stderr"; then fail "$name: message lacks '$expected': $(cat "$work/stderr")"; return; fi
  # The temporary names of model/io/atomic_write.cc: OUT.tmp.PID (a file), .tmpPID-OUT (a directory).
  local escaped
  escaped=$(basename "$out" | sed 's/[][\.*^$()+?{}|]/\\&/g')
  if [ -e "$out" ] || ls -A "$(dirname "$out")" 2>/dev/null | grep -qE "^($escaped\.tmp\.[0-9]+|\.tmp[0-9]+-$escaped)\$"; then
    fail "$name: left output behind at $out"
    return
  fi
  pass
}

# --- happy paths -------------------------------------------------------------------
# Projecting points needs no image codecs: OpenCV's imgcodecs and videoio (with the ~240
# libraries they bring) are loaded only when a file of pixels is read or written
# (model/io/codecs/image_codecs.h).
if ldd "$omnical" | grep -qE "libopencv_(imgcodecs|videoio)"; then
  fail "the CLI links OpenCV's imgcodecs or videoio: $(ldd "$omnical" | grep -E "libopencv_(imgcodecs|videoio)" | tr -s ' \n' ' ')"
else
  pass
fi
cat >"$work/pixels.csv" <<'CSV'
# pixels of the seed SPH sensor: centre, mid-field, half a pixel inside the rim, a corner
u,v
499.5,499.5
700,450
999,499.5
5,5
CSV
if "$omnical" unproject --sensor "$sensors/ohte-sph.yaml" --pixels "$work/pixels.csv" --out "$work/rays.csv"; then
  statuses=$(tail -n +2 "$work/rays.csv" | cut -d, -f7 | tr '\n' ' ')
  # The centre pixel sees the camera's own reflection (body radius 15 mm in the sensor file).
  [ "$statuses" = "occluded_by_camera ok ok outside_mirror " ] && pass || fail "unproject statuses: $statuses"
else
  fail "unproject exited $?"
fi

# Points 10 rim radii along the rays, projected back, land on the pixels they came from
# (the library tests bound this at 1e-6 px; through 15-digit CSV text 1e-6 px still holds).
# Both rows must come back "ok": a NaN pixel or another status counts as infinitely off
# (the rim pixel itself, 999.5, unprojects ok but its point projects back outside_mirror:
# this check skipped it unnoticed until the status was read).
awk -F, 'NR > 1 && $7 == "ok" { d = 439; printf "%.17g,%.17g,%.17g\n", $1 + d*$4, $2 + d*$5, $3 + d*$6 }' \
  "$work/rays.csv" >"$work/points.csv"
if "$omnical" project --sensor "$sensors/ohte-sph.yaml" --points "$work/points.csv" --out "$work/back.csv"; then
  worst=$(paste -d, <(tail -n +4 "$work/pixels.csv" | head -2) <(tail -n +2 "$work/back.csv") |
    awk -F, '{ du = $1 - $3; dv = $2 - $4; e = sqrt(du*du + dv*dv); if ($5 != "ok" || !(e == e)) bad = 1; else if (e > w) w = e }
             END { if (bad || NR != 2) printf "inf"; else printf "%.3g", w + 0 }')
  [ "$worst" != inf ] && awk -v w="$worst" 'BEGIN { exit !(w + 0 < 1e-6) }' && pass || fail "project round trip error $worst px"
  [ -z "$(ls "$work" | grep '\.tmp\.')" ] && pass || fail "temporary file left behind"
else
  fail "project exited $?"
fi

# Standard output when --out is absent.
"$omnical" project --sensor "$sensors/ohte-edi.yaml" --points "$work/points.csv" | grep -q "^u,v,status$" && pass ||
  fail "project to stdout"

"$omnical" --help >/dev/null && "$omnical" project --help >/dev/null && "$omnical" unproject --help >/dev/null && pass ||
  fail "--help"

# --- bad input -----------------------------------------------------------------------
printf 'camera: { model: pinhole, image_size: [1000, 1000\n' >"$work/malformed.yaml"
sed 's/profile: sphere/profile: cone/' "$sensors/ohte-sph.yaml" >"$work/unknown_profile.yaml"
sed 's/A: 49/A: -49/' "$sensors/ohte-sph.yaml" >"$work/negative_radius.yaml"
sed 's/m: 180.429[0-9]*/m: -1/' "$sensors/ohte-sph.yaml" >"$work/m_inside.yaml"
printf 'X,Y,Z\n1,2,3\n4,five,6\n' >"$work/text.csv"
printf 'X,Y,Z\n1,2,3\n4,nan,6\n' >"$work/nan.csv"
printf 'X,Y\n1,2\n' >"$work/short.csv"
: >"$work/empty.csv"

expect_error missing_sensor "nope.yaml: file not found" -- project --sensor "$work/nope.yaml" --points "$work/points.csv" --out "$work/out.csv"
expect_error malformed_yaml "malformed.yaml: line" -- project --sensor "$work/malformed.yaml" --points "$work/points.csv" --out "$work/out.csv"
expect_error unknown_profile "mirror.profile: unknown profile 'cone'" -- project --sensor "$work/unknown_profile.yaml" --points "$work/points.csv" --out "$work/out.csv"
expect_error negative_radius "negative_radius.yaml: mirror.A: must be > 0" -- project --sensor "$work/negative_radius.yaml" --points "$work/points.csv" --out "$work/out.csv"
expect_error m_inside_mirror "m_inside.yaml: pose.m: must be > 0" -- project --sensor "$work/m_inside.yaml" --points "$work/points.csv" --out "$work/out.csv"
expect_error csv_text "text.csv:3: column 2: 'five' is not a number" -- project --sensor "$sensors/ohte-sph.yaml" --points "$work/text.csv" --out "$work/out.csv"
expect_error csv_nan "nan.csv:3: column 2: value is not finite" -- project --sensor "$sensors/ohte-sph.yaml" --points "$work/nan.csv" --out "$work/out.csv"
expect_error csv_short "short.csv:2: expected at least 3 columns" -- project --sensor "$sensors/ohte-sph.yaml" --points "$work/short.csv" --out "$work/out.csv"
expect_error csv_empty "empty.csv: no numeric rows" -- project --sensor "$sensors/ohte-sph.yaml" --points "$work/empty.csv" --out "$work/out.csv"
expect_error pixels_text "text.csv:3: column 2" -- unproject --sensor "$sensors/ohte-sph.yaml" --pixels "$work/text.csv" --out "$work/out.csv"
expect_error missing_option "--points is required" -- project --sensor "$sensors/ohte-sph.yaml"
expect_error unknown_command "A subcommand is required (see --help)" -- frobnicate
expect_error unwritable_output "cannot create output file" -- project --sensor "$sensors/ohte-sph.yaml" --points "$work/points.csv" --out "/nonexistent-dir/out.csv"

# --- characterize and parallax ---------------------------------------------------------
# json FILE KEY: a top-level number from a JSON file.
json() { python3 -c "import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])" "$1" "$2"; }
# near VALUE EXPECTED TOLERANCE NAME
# A value that is no finite number (empty, None: a NaN in the JSON, nan) fails.
near() { within "$1" "$2" "$3" && pass || fail "$4: $1, expected $2 +- $3"; }

if "$omnical" -q characterize --sensor "$sensors/ohte-sph.yaml" --lens-f 11.6 --f-number 4 --pixel-um 5.2 \
    --focus-mm 212 --out "$work/char"; then
  # Seed Table 1, Sec. 3.3 and Eq. 32 (SEED-NOTES values).
  near "$(json "$work/char/summary.json" rim_omega_deg)" 135.0 0.05 "rim_omega_deg"
  near "$(json "$work/char/summary.json" rim_theta_deg)" 12.0 0.05 "rim_theta_deg"
  near "$(json "$work/char/summary.json" depth_of_field_mm)" 13.9 0.05 "depth_of_field_mm at L0 = 212"
  near "$(json "$work/char/summary.json" mean_solid_angle_per_pixel_deg2)" 0.0448 0.0001 "mean solid angle per pixel"
  for f in characteristics.csv fig04_ray_trace.png fig05_image_height.png fig06_viewpoints.png fig07_area_aspect.png \
      fig08_image_forming.png fig09_blur.png; do
    [ -s "$work/char/$f" ] && pass || fail "characterize did not write $f"
  done
  [ "$(head -c 8 "$work/char/fig04_ray_trace.png" | od -An -tx1 | tr -d ' ')" = "89504e470d0a1a0a" ] && pass ||
    fail "fig04 is not a PNG"
else
  fail "characterize exited $?"
fi
"$omnical" -q characterize --sensor "$sensors/ohte-svp.yaml" --out "$work/char-svp" &&
  near "$(json "$work/char-svp/summary.json" viewpoint_spread_mm)" 0 1e-9 "SVP viewpoint spread" || fail "characterize svp"
"$omnical" -q characterize --sensor "$sensors/ohte-sph-misaligned.yaml" --out "$work/char-tilted" &&
  grep -q "aligned counterpart" "$work/char-tilted/summary.json" && pass || fail "characterize misaligned"

# Fig. 15: spherical mirror, best V0.
for case in "7 4.75 0.2" "40 0.91 0.05"; do
  set -- $case
  if "$omnical" -q parallax --sensor "$sensors/ohte-sph.yaml" --n "$1" --out "$work/par$1"; then
    near "$(json "$work/par$1/parallax.json" max_abs_error_px)" "$2" "$3" "parallax n = $1"
    [ -s "$work/par$1/error_map.png" ] && [ -s "$work/par$1/parallax.png" ] && [ -s "$work/par$1/parallax.csv" ] && pass ||
      fail "parallax n = $1 outputs"
  else
    fail "parallax n = $1 exited $?"
  fi
done
# The same object distance in mm, and a given V0, are taken as given.
"$omnical" -q parallax --sensor "$sensors/ohte-sph.yaml" --distance-mm 307.3 --v0 11.0 --out "$work/parmm" &&
  near "$(json "$work/parmm/parallax.json" v0_mm)" 11.0 1e-12 "parallax --v0" || fail "parallax --distance-mm"

sed 's/image_size: \[1000, 1000\]/image_size: [600, 600]/' "$sensors/ohte-sph.yaml" >"$work/small_image.yaml"
expect_error parallax_n_zero "--n" -- parallax --sensor "$sensors/ohte-sph.yaml" --n 0 --out "$work/out.csv"
expect_error parallax_n_negative "--n" -- parallax --sensor "$sensors/ohte-sph.yaml" --n -3 --out "$work/out.csv"
expect_error parallax_no_distance "--n or --distance-mm" -- parallax --sensor "$sensors/ohte-sph.yaml" --out "$work/out.csv"
expect_error parallax_both "excludes" -- parallax --sensor "$sensors/ohte-sph.yaml" --n 7 --distance-mm 300 --out "$work/out.csv"
expect_error characterize_f_number "--f-number" -- characterize --sensor "$sensors/ohte-sph.yaml" --f-number -4 --out "$work/out.csv"
expect_error characterize_pixel_zero "--pixel-um" -- characterize --sensor "$sensors/ohte-sph.yaml" --pixel-um 0 --out "$work/out.csv"
expect_error characterize_rim_outside "the mirror rim images outside the 600 x 600 image" -- characterize --sensor "$work/small_image.yaml" --out "$work/out.csv"

# --- target and render ---------------------------------------------------------------------
targets=$source_dir/datasets-synthetic/targets
if "$omnical" -q target --spec "$targets/aprilgrid-6x6-30mm.yaml" --out "$work/grid.png" --dpi 50; then
  # 243 mm at 50 dpi = 478 px (true scale).
  size=$(python3 -c "import struct,sys; d=open(sys.argv[1],'rb').read(24); print(*struct.unpack('>II', d[16:24]))" "$work/grid.png")
  [ "$size" = "478 478" ] && pass || fail "target png size $size, expected 478 478"
else
  fail "target png"
fi
"$omnical" -q target --spec "$targets/checkerboard-8x6-30mm.yaml" --out "$work/cb.svg" &&
  grep -q 'width="330mm" height="270mm"' "$work/cb.svg" && pass || fail "target svg size"
"$omnical" -q target --spec "$targets/aprilgrid-6x6-30mm.yaml" --out "$work/grid.pdf" &&
  grep -aq "MediaBox \[0 0 688.818897" "$work/grid.pdf" && tail -c 6 "$work/grid.pdf" | grep -q "%%EOF" && pass ||
  fail "target pdf"
expect_error target_format "unknown format '.jpg'" -- target --spec "$targets/aprilgrid-6x6-30mm.yaml" --out "$work/out.jpg"
# OMNICAL_CODECS_PLUGIN names the one image codecs plugin to load (model/io/codecs/
# image_codecs.h): a missing file, or the plugin of another build, is refused by name.
OMNICAL_CODECS_PLUGIN=$work/no-plugin.so expect_error codecs_plugin_missing \
  "OMNICAL_CODECS_PLUGIN: $work/no-plugin.so: no such file; it must name libomnical_codecs_plugin.so" -- \
  target --spec "$targets/aprilgrid-6x6-30mm.yaml" --out "$work/out.csv.png"
OMNICAL_CODECS_PLUGIN=$other_build_plugin expect_error codecs_plugin_of_another_build \
  "OMNICAL_CODECS_PLUGIN: $other_build_plugin: from another build (another build of omnical; this program's: omnical " -- \
  target --spec "$targets/aprilgrid-6x6-30mm.yaml" --out "$work/out.csv.png"
# Without it, a prefix moved as a whole finds its own plugin (<prefix>/bin/omnical ->
# <prefix>/<libdir>/omnical), but not one others may write (anyone can make /tmp/lib).
moved=$work/moved-prefix
mkdir -p "$moved/bin" "$moved/$libdir/omnical"
cp "$omnical" "$moved/bin/omnical"
cp "$codecs_plugin" "$moved/$libdir/omnical/"
chmod 755 "$moved/$libdir/omnical" "$moved/$libdir/omnical/libomnical_codecs_plugin.so"  # whatever the umask
"$moved/bin/omnical" -q target --spec "$targets/aprilgrid-6x6-30mm.yaml" --dpi 20 --out "$work/moved.png" &&
  [ -s "$work/moved.png" ] && pass || fail "a moved prefix's omnical did not write a PNG through its own plugin"
chmod o+w "$moved/$libdir/omnical"
omnical=$moved/bin/omnical expect_error codecs_plugin_others_may_write \
  "$moved/$libdir/omnical/libomnical_codecs_plugin.so (not loaded: others may write $moved/$libdir/omnical)" -- \
  target --spec "$targets/aprilgrid-6x6-30mm.yaml" --out "$work/out.csv.png"

cat >"$work/scene.yaml" <<YAML
sensor: $sensors/ohte-sph.yaml
render: { samples_per_pixel: 1 }
targets: { board: $targets/aprilgrid-6x6-30mm.yaml }
views:
  - { name: one, board: { omega_deg: 70, distance_n: 6 } }
YAML
if "$omnical" -q render --scene "$work/scene.yaml" --out "$work/render"; then
  [ -s "$work/render/one.png" ] && [ -s "$work/render/sensor.yaml" ] && [ -s "$work/render/scene.json" ] && pass ||
    fail "render outputs"
  visible=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['targets'][0]['visible_corners'])" "$work/render/one.json")
  [ "$visible" = 144 ] && pass || fail "render ground truth: $visible visible corners, expected 144"
  # The saved sensor is the one rendered: it loads and projects the same.
  "$omnical" project --sensor "$work/render/sensor.yaml" --points "$work/points.csv" | cmp -s - <(
    "$omnical" project --sensor "$sensors/ohte-sph.yaml" --points "$work/points.csv") && pass || fail "render sensor.yaml"
else
  fail "render exited $?"
fi
sed 's/omega_deg: 70/omega_deg: 170/' "$work/scene.yaml" >"$work/scene_behind.yaml"
printf 'target_type: aprilgrid\ntagCols: 6\ntagRows: 6\ntagSize: 0.03\ntagSpacing: 0.3\ntagFamily: tag99\n' >"$work/tag99.yaml"
printf 'target_type: aprilgrid\ntagCols: 6\ntagRows: 6\ntagSize: 0\ntagSpacing: 0.3\n' >"$work/zero.yaml"
sed "s#$targets/aprilgrid-6x6-30mm.yaml#$work/tag99.yaml#" "$work/scene.yaml" >"$work/scene_tag99.yaml"
sed "s#$targets/aprilgrid-6x6-30mm.yaml#$work/zero.yaml#" "$work/scene.yaml" >"$work/scene_zero.yaml"
printf 'sensor: [unclosed\n' >"$work/scene_bad.yaml"
expect_error render_target_behind "views[0].board: the target centre is not seen in the mirror" -- render --scene "$work/scene_behind.yaml" --out "$work/out.csv"
expect_error render_missing_family "tagFamily: unknown tag family 'tag99'" -- render --scene "$work/scene_tag99.yaml" --out "$work/out.csv"
expect_error render_zero_size "tagSize: must be > 0" -- render --scene "$work/scene_zero.yaml" --out "$work/out.csv"
expect_error render_unreadable "scene_bad.yaml: line" -- render --scene "$work/scene_bad.yaml" --out "$work/out.csv"
expect_error render_missing "nope.yaml: file not found" -- render --scene "$work/nope.yaml" --out "$work/out.csv"
expect_error target_zero_size "zero.yaml: tagSize: must be > 0" -- target --spec "$work/zero.yaml" --out "$work/out.png"

# --- detect and calibrate (the committed renders of the misaligned sphere) ---------------
rendered=$source_dir/datasets-synthetic/rendered/ohte-sph-misaligned-near
grid=$targets/aprilgrid-6x6-30mm.yaml
guess=$sensors/ohte-sph-misaligned-guess.yaml
if "$omnical" -q detect --target "$grid" --images "$rendered" --out "$work/det.json"; then
  # Against the ground truth: recall of visible corners and pixel error (raw AprilTag:
  # 96.9% and 0.26 px RMS measured; the bounds leave room, not slack for regressions).
  python3 - "$work/det.json" <<'PYCHECK' && pass || fail "detect accuracy"
import json, math, sys
det = json.load(open(sys.argv[1]))
errors, found, visible = [], 0, 0
for image in det["images"]:
    truth = {c["id"]: c for c in json.load(open(image["image"][:-4] + ".json"))["targets"][0]["corners"]}
    ids = {c["id"] for c in image["corners"]}
    visible += sum(c["visible"] for c in truth.values())
    found += sum(truth[i]["visible"] for i in ids)
    errors += [math.dist(c["pixel"], truth[c["id"]]["pixel"]) for c in image["corners"]]
rms = math.sqrt(sum(e * e for e in errors) / len(errors))
print(f"detect: recall {found / visible:.3f}, RMS {rms:.3f} px")
sys.exit(0 if found / visible > 0.95 and rms < 0.35 else 1)
PYCHECK
else
  fail "detect exited $?"
fi
if "$omnical" -q calibrate --target "$grid" --detections "$work/det.json" --sensor "$guess" --out "$work/cal"; then
  near "$(json "$work/cal/calibration.json" rms_px)" 0.15 0.15 "calibrate RMS (px)"
  [ "$(json "$work/cal/calibration.json" converged)" = True ] && pass || fail "calibrate did not converge"
  [ -s "$work/cal/sensor.yaml" ] && [ -s "$work/cal/report/residual_histogram.png" ] && [ -s "$work/cal/report/coverage.png" ] &&
    [ -s "$work/cal/report/per_view_rms.png" ] && [ -s "$work/cal/report/residuals_view0.png" ] && pass || fail "calibrate outputs"
  "$omnical" project --sensor "$work/cal/sensor.yaml" --points "$work/points.csv" >/dev/null && pass || fail "calibrated sensor.yaml does not load"
else
  fail "calibrate exited $?"
fi
# Leave-one-image-out: one spread per parameter. On 5 of the 8 views: 5 refits, not 8
# (the library's tests check the spreads' values).
python3 -c "import json,sys; d=json.load(open(sys.argv[1])); d['images']=d['images'][:5]; json.dump(d, open(sys.argv[2], 'w'))" \
  "$work/det.json" "$work/det_five.json"
"$omnical" -q calibrate --target "$grid" --detections "$work/det_five.json" --sensor "$guess" --out "$work/cal_loo" --leave-one-out 2>/dev/null &&
  python3 -c "import json,sys; d=json.load(open(sys.argv[1])); l=d['leave_one_out']; sys.exit(0 if set(l) == set(d['parameters']) and l['fx_px']['max'] >= l['fx_px']['min'] else 1)" "$work/cal_loo/calibration.json" &&
  pass || fail "calibrate --leave-one-out"
# Generalisation: 2 views held out and evaluated, two halves compared; then omnical diff
# between two calibrations. On these 8 renders (detected corners, ~0.15 px) the held-out
# views fit within 2x the training RMS (measured 0.04 vs 0.11 px, outliers included) and
# the halves of 3 views each differ by 0.32 px RMS at 1 m (bound 1 px: a sanity bound, the
# library tests check the numbers against known answers).
if "$omnical" -q calibrate --target "$grid" --detections "$work/det.json" --sensor "$guess" --out "$work/cal_cv" \
    --holdout 2 --cross-validate --cross-validate-distance-mm 1000 --board-warp 2>/dev/null; then
  python3 - "$work/cal_cv/calibration.json" <<'PYCV' && pass || fail "calibrate --holdout --cross-validate"
import json, sys
d = json.load(open(sys.argv[1]))
h, c = d["holdout"], d["cross_validation"]
ok = len(h["views"]) == 2 and h["corners"] > 0 and 0 < h["rms_px"] < 2 * h["training_rms_px"]
ok &= not any(v in d["per_view_rms_px"] for v in h["views"])  # kept out of the fit
ok &= c["distance_mm"] == 1000 and c["grid_points"] > 100 and 0 <= c["diff_rms_px"] < 1.0
ok &= sorted(c["halves"][0] + c["halves"][1]) == sorted(d["per_view_rms_px"])
# The same halves with one alignment fitted where the boards were, as the predicted error.
b = c["aligned_at_boards"]
ok &= c["aligned_at_mm"] == 1000 and b["distance_mm"] == 1000 and b["grid_points"] > 100
ok &= b["aligned_at_mm"] == d["predicted_error"][0]["aligned_at_mm"] == d["predicted_error"][0]["distance_mm"]
w = d["board_warp"]  # the rendered board is flat: its warp is zero within 3 std
ok &= 0 < w["std_x_mm"] < 1 and 0 < w["std_y_mm"] < 1 and abs(w["x_mm"]) < 3 * w["std_x_mm"] and abs(w["y_mm"]) < 3 * w["std_y_mm"]
print(f"holdout {h['rms_px']:.3f} vs {h['training_rms_px']:.3f} px; halves differ {c['diff_rms_px']:.3f} px "
      f"({b['diff_rms_px']:.3f} aligned at the boards' {b['aligned_at_mm']:.0f} mm); "
      f"warp {w['x_mm']:.3f} +- {w['std_x_mm']:.3f}, {w['y_mm']:.3f} +- {w['std_y_mm']:.3f} mm")
sys.exit(0 if ok else 1)
PYCV
  [ -s "$work/cal_cv/report/cross_validation.png" ] && [ -s "$work/cal_cv/report/holdout.png" ] && pass ||
    fail "calibrate --cross-validate figures"
  # A calibration against itself differs by nothing; against the 6-view one, by little.
  out=$("$omnical" diff "$work/cal" "$work/cal" --distance-mm 1000 --out "$work/diff_self") &&
    python3 -c "import json,sys; d=json.load(open(sys.argv[1])); sys.exit(0 if d['diff_rms_px'] < 1e-9 and d['grid_points'] > 100 else 1)" \
      "$work/diff_self/diff.json" && [ -s "$work/diff_self/diff.png" ] && pass || fail "diff of a calibration with itself: $out"
  "$omnical" diff "$work/cal" "$work/cal_cv/sensor.yaml" --field "$work/det.json" --distance-mm 1000 --out "$work/diff_cv" |
    grep -q "^at 1000 mm over" && python3 -c "import json,sys; d=json.load(open(sys.argv[1])); sys.exit(0 if 0 < d['diff_rms_px'] < 0.5 else 1)" \
      "$work/diff_cv/diff.json" && pass || fail "diff of two calibrations"
else
  fail "calibrate --holdout --cross-validate exited $?"
fi
expect_error diff_missing_sensor "nowhere.yaml" -- diff "$work/cal" "$work/nowhere.yaml" --out "$work/out.csv"
expect_error diff_other_camera "image_size: differs" -- diff "$work/cal" "$sensors/ohte-sph.yaml" --out "$work/out.csv"
expect_error diff_align_at_zero "--align-at-mm: must be > 0" -- diff "$work/cal" "$work/cal" --align-at-mm 0
expect_error diff_align_at_far "--align-at-mm: the object distance must be at most" -- diff "$work/cal" "$work/cal" \
  --align-at-mm 1e9
expect_error diff_align_and_not "--align-at-mm excludes --no-align" -- diff "$work/cal" "$work/cal" --align-at-mm 300 \
  --no-align
# Bad input: nothing may be written.
python3 - "$work/det.json" "$work" <<'PYBAD'
import json, sys
det = json.load(open(sys.argv[1])); work = sys.argv[2]
two = dict(det); two["images"] = det["images"][:2]; json.dump(two, open(work + "/det_two.json", "w"))
same = dict(det); same["images"] = [det["images"][0]] * 4; json.dump(same, open(work + "/det_same.json", "w"))
size = dict(det); size["image_size"] = [1000, 1000]; json.dump(size, open(work + "/det_size.json", "w"))
# As a file from before detections recorded their board: its ids are then checked one by one.
undescribed = dict(det); undescribed.pop("target_description"); json.dump(undescribed, open(work + "/det_undescribed.json", "w"))
PYBAD
printf 'target_type: aprilgrid\ntagCols: 6\ntagRows: 6\ntagSize: 0.03\ntagSpacing: 0.3\ncodeOffset: 200\n' >"$work/other_ids.yaml"
calibrate_error() {
  local name=$1 expected=$2
  shift 2
  rm -rf "$work/cal_bad"
  expect_error "$name" "$expected" -- calibrate --sensor "$guess" --out "$work/cal_bad" "$@"
  [ ! -e "$work/cal_bad" ] && pass || fail "$name: left $work/cal_bad behind"
}
calibrate_error calibrate_too_few_views "too few" --target "$grid" --detections "$work/det_two.json"
calibrate_error calibrate_holdout_too_many "holdout: 6 views held out of 8 usable leave fewer than 3 for the fit" \
  --target "$grid" --detections "$work/det.json" --holdout 6
calibrate_error calibrate_halves_too_small "--cross-validate: half 2 has 2 views (need >= 3 per half" \
  --target "$grid" --detections "$work/det.json" --holdout 3 --cross-validate
calibrate_error calibrate_knots_range "--knots: must be 4..16 (or auto)" --target "$grid" --detections "$work/det.json" \
  --profile spline --knots 3
calibrate_error calibrate_knots_text "--knots: expected a knot count (4..16) or 'auto', got 'six'" --target "$grid" \
  --detections "$work/det.json" --profile spline --knots six
calibrate_error calibrate_knots_not_spline "only the spline profile has knots (profile: sphere; ask for --profile spline)" \
  --target "$grid" --detections "$work/det.json" --knots auto
calibrate_error calibrate_one_pose "all views show the target at one pose" --target "$grid" --detections "$work/det_same.json"
calibrate_error calibrate_spec_matches_nothing "matches no corner id" --target "$work/other_ids.yaml" --detections "$work/det_undescribed.json"
calibrate_error calibrate_another_board "the corners were found on another board (aprilgrid 6 x 6 tag36h11 from id 0" \
  --target "$work/other_ids.yaml" --detections "$work/det.json"
calibrate_error calibrate_image_size "image_size: 1000 x 1000 differs from the sensor's 1040 x 1040" --target "$grid" --detections "$work/det_size.json"
calibrate_error calibrate_unknown_block "--fix: unknown block 'focal'" --target "$grid" --detections "$work/det.json" --fix focal
calibrate_error calibrate_unknown_tolerance "--tolerance: tolerances.B_mm: not a parameter of this sphere / pinhole sensor" \
  --target "$grid" --detections "$work/det.json" --tolerance B_mm=1
calibrate_error calibrate_tolerance_syntax "--tolerance: 'm_mm' is not name=value" --target "$grid" --detections "$work/det.json" --tolerance m_mm
printf 'camera: { model: pinhole, image_size: [1040, 1040], fx: 2350, fy: 2350, cx: 519.5, cy: 519.5, k1: 0, k2: 0 }\nmirror: { profile: sphere, rim_radius: 43.9, A: 50 }\npose: { m: 180 }\ntolerances: { m_mm: -2 }\n' >"$work/guess_bad_tolerance.yaml"
rm -rf "$work/cal_bad"
expect_error calibrate_guess_tolerance "guess_bad_tolerance.yaml: tolerances.m_mm: must be a positive number" -- \
  calibrate --target "$grid" --detections "$work/det.json" --sensor "$work/guess_bad_tolerance.yaml" --out "$work/cal_bad"
# The error at the user's distance: tolerances from the guess file and the flag, one map
# per asked distance, the whole covariance, and the predicted error in calibration.json.
sed 's/^pose: .*/&\ntolerances: { m_mm: 2, decenter_mm: 1 }/' "$guess" >"$work/guess_tolerances.yaml"
if "$omnical" -q calibrate --target "$grid" --detections "$work/det.json" --sensor "$work/guess_tolerances.yaml" \
  --tolerance principal_point_px=10 --distance-n 2 --distance-mm 5000 --out "$work/cal_trust" 2>"$work/trust.err"; then
  python3 - "$work/cal_trust/calibration.json" <<'PYTRUST' && pass || fail "calibrate: predicted error, tolerances, covariance"
import json, sys
d = json.load(open(sys.argv[1]))
p = d["predicted_error"]
assert [round(e["n_rim_radii"], 3) for e in p] == [round(5000 / 43.9, 3), 2.0], p   # --distance-mm first
assert all(e["max_px"] >= e["median_px"] > 0 for e in p), p
assert p[1]["max_px"] > p[0]["max_px"], p          # near objects are the uncertain ones
# Per parameter: the pairs expanded (decenter_mm from the file, principal_point_px from the flag).
assert d["tolerances"] == {"m_mm": 2, "decenter_x_mm": 1, "decenter_y_mm": 1, "cx_px": 10, "cy_px": 10}, d["tolerances"]
names = d["covariance"]["names"]; c = d["covariance"]["matrix"]
assert len(c) == len(names) and all(abs(c[i][i] ** 0.5 - d["parameters"][n]["std"]) < 1e-9 * (1 + c[i][i] ** 0.5) for i, n in enumerate(names))
assert d["outlier_threshold_px"] >= 0.5 and d["rim_radius_mm"]["fitted"] >= d["rim_radius_mm"]["guess"]
PYTRUST
  [ -s "$work/cal_trust/report/predicted_error_0.png" ] && [ -s "$work/cal_trust/report/predicted_error_1.png" ] &&
    [ ! -e "$work/cal_trust/report/predicted_error_2.png" ] && pass || fail "calibrate: predicted error maps"
  # A threshold no fit can meet: the warning names the distance and what would help.
  "$omnical" -q calibrate --target "$grid" --detections "$work/det.json" --sensor "$guess" --distance-n 2 \
    --max-predicted-error-px 0.001 --out "$work/cal_trust2" 2>"$work/trust2.err" &&
    grep -q "warning: predicted projection error up to .* at .* (n = 2.00) exceeds 0.00 px.*would help" "$work/trust2.err" &&
    grep -q "predicted projection error" "$work/cal_trust2/calibration.json" && pass ||
    fail "calibrate: predicted error warning: $(cat "$work/trust2.err")"
  # A distant giant: view 3's corners replaced by those of a board 4 times the size, 4
  # times as far (projected through the rendered scene's true sensor from the first fit's
  # pose). Measured: through the fit it was in it escaped the board-size check; checked as
  # the strongest suspect through a fit without it (calib/board_size_screen.h) it fits best
  # at 3.72 x its size and is left out. Before that re-check it dragged the fit into a
  # wrong basin (fx -23 %, m -59 %, A -46 % at 0.14 px RMS without tolerances), which only
  # the design tolerances showed (m 6.7 tolerances from its design). Now it must be refused.
  python3 - "$work/cal_trust/calibration.json" "$work/det.json" "$work/giant_points.csv" <<'PYGIANT'
import json, sys
cal, det = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
image = det["images"][3]["image"]
w, x, y, z = cal["poses"][image]["camera_from_target_quaternion_wxyz"]
t = cal["poses"][image]["camera_from_target_translation_mm"]
R = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
rows = []
for tag in range(36):                         # 6 x 6 tags of 30 mm, 9 mm gaps (calib/target.h)
    x0, y0 = 39.0 * (tag % 6), 39.0 * (tag // 6)
    for k, (dx, dy) in enumerate([(0, 0), (30, 0), (30, 30), (0, 30)]):
        p = [4 * (x0 + dx), 4 * (y0 + dy), 0.0]
        rows.append([sum(R[i][j] * p[j] for j in range(3)) + 4 * t[i] for i in range(3)])
open(sys.argv[3], "w").write("X,Y,Z\n" + "".join("%.9g,%.9g,%.9g\n" % tuple(r) for r in rows))
PYGIANT
  "$omnical" project --sensor "$rendered/sensor.yaml" --points "$work/giant_points.csv" --out "$work/giant_pixels.csv" &&
    python3 - "$work/det.json" "$work/giant_pixels.csv" "$work/det_giant.json" <<'PYSWAP' &&
import json, sys
det = json.load(open(sys.argv[1]))
pixels = [r.split(",") for r in open(sys.argv[2]).read().split() if r[0] != "u"]
det["images"][3]["corners"] = [{"id": i, "pixel": [float(p[0]), float(p[1])]} for i, p in enumerate(pixels) if p[2] == "ok"]
json.dump(det, open(sys.argv[3], "w"))
PYSWAP
    "$omnical" -q calibrate --target "$grid" --detections "$work/det_giant.json" --sensor "$guess" \
      --tolerance m_mm=2,decenter_mm=1,tilt_deg=1,principal_point_px=10 --out "$work/cal_giant" 2>"$work/giant.err" &&
    grep -qE "near002.png: view left out of the fit: the board .*fits as a board" \
      "$work/giant.err" && pass || fail "calibrate: a distant giant's view not flagged: $(cat "$work/giant.err")"
else
  fail "calibrate --distance-n --tolerance exited $?: $(cat "$work/trust.err")"
fi
# calibrate --images: detection inside calibrate (through the guess: virtual views and
# refinement in patches; two detection passes; measured 0.033 px RMS), detections.json beside the results.
if "$omnical" -q calibrate --target "$grid" --images "$rendered" --sensor "$guess" --distance-n 2 --distance-n 7 \
  --out "$work/cal_img" 2>/dev/null; then
  # The trust issue's near-only, k1/k2-free case from rendered images: the predicted error
  # at n = 2 and 7 against the actual one, omnical diff of the true sensor and the
  # calibrated one over the corners' annulus, after the rigid alignment fitted at the
  # boards' median distance (the prediction's measure: diff --align-at-mm) and without it
  # (in_camera_frame_*). Each prediction's 3-sigma bound covers the actual error, and
  # where the fit is off by more than the 0.3 px warning threshold the warning fires.
  python3 - "$omnical" "$rendered/sensor.yaml" "$work/cal_img" "$work" <<'PYACTUAL' && pass || fail "calibrate --images: predicted vs actual error"
import json, subprocess, sys
omnical, truth, cal, work = sys.argv[1:5]
d = json.load(open(cal + "/calibration.json"))
assert [round(e["n_rim_radii"]) for e in d["predicted_error"]] == [2, 7], d["predicted_error"]  # the two asked
for e in d["predicted_error"]:
    assert 88 < e["aligned_at_mm"] < 440, e  # the boards' median distance, 2-10 rim radii
    actual = {}
    for align in (True, False):
        out = "%s/pd_%d_%d" % (work, round(e["n_rim_radii"]), align)
        how = ["--align-at-mm", "%.6f" % e["aligned_at_mm"]] if align else ["--no-align"]
        subprocess.run([omnical, "-q", "diff", truth, cal, "--distance-mm", "%.6f" % e["distance_mm"], "--field",
                        cal + "/detections.json", "--out", out] + how, check=True)
        diff = json.load(open(out + "/diff.json"))
        assert not align or abs(diff["aligned_at_mm"] - e["aligned_at_mm"]) < 1e-5, diff["aligned_at_mm"]
        actual[align] = diff["diff_max_px"]
    print("n = %.0f: actual worst %.3f px aligned (predicted %.3f), %.2f px in the camera's frame (predicted %.2f)" % (
        e["n_rim_radii"], actual[True], e["max_px"], actual[False], e["in_camera_frame_max_px"]))
    for worst, predicted in ((actual[True], e["max_px"]), (actual[False], e["in_camera_frame_max_px"])):
        assert worst <= 3 * predicted and (worst <= 0.3 or predicted > 0.3), (e, actual)
PYACTUAL
  near "$(json "$work/cal_img/calibration.json" rms_px)" 0.05 0.05 "calibrate --images RMS (px)"
  # Noise-free renders: < 0.5 % of the corners flagged as outliers (the trust issue).
  python3 -c "import json,sys; d=json.load(open(sys.argv[1])); sys.exit(0 if d['outliers'] < 0.005 * d['observations'] else 1)" \
    "$work/cal_img/calibration.json" && pass || fail "calibrate --images: outliers on a noise-free render"
  [ -s "$work/cal_img/detections.json" ] && pass || fail "calibrate --images wrote no detections.json"
else
  fail "calibrate --images exited $?"
fi
# No guess: the rim circle starts an unknown-mirror polynomial, and the lens, the mirror
# family and a pinhole's p1, p2 are chosen by held-out folds by default. Measured
# (2026-11-30): the pinhole predicts the held-out views at 0.341 px against the
# orthographic's 4.71; through it the even asphere (a conic: this mirror is a sphere) at
# 0.114 px against the polynomial's 0.341; with p1, p2 fitted a fold fits no valid sensor,
# so they are held (all 1080 corners for each). RMS 0.037 px, 0.092 px from the true sensor
# at 300 mm. With the polynomial kept (until 2026-11-30) p1, p2 were fitted: RMS 0.066 px,
# 0.25 px from the truth. Until 2026-11-29 a view by the rim (near006) had no pose through
# the pinhole's fold fits, and the orthographic was kept: RMS 0.42 px, 2.05 px from the
# truth (docs/calibrate.md).
if "$omnical" -q calibrate --target "$grid" --images "$rendered" --out "$work/cal_rim" 2>/dev/null &&
  "$omnical" -q diff "$rendered/sensor.yaml" "$work/cal_rim" --distance-mm 300 --field "$work/cal_rim/detections.json" \
    --out "$work/diff_rim" >/dev/null; then
  near "$(json "$work/cal_rim/calibration.json" rms_px)" 0.04 0.02 "calibrate from the rim circle RMS (px)"
  python3 -c "import json,sys; d=json.load(open(sys.argv[1])); r=d['rim_circle']; sys.exit(0 if d['converged'] and abs(r['radius_px'] - 499.5) < 2 and 'k' in d['parameters'] else 1)" "$work/cal_rim/calibration.json" &&
    pass || fail "calibrate from the rim circle: rim or parameters"
  # Every rendered board is the target: none left out (the board-size check needs a design;
  # through the rim-circle model it refused 3 of the 8).
  python3 -c "import json,sys; d=json.load(open(sys.argv[1])); sys.exit(0 if 'views_left_out' not in d and len(d['poses']) == int(sys.argv[2]) else 1)" \
    "$work/cal_rim/calibration.json" "$(ls "$rendered"/*.png | wc -l)" && pass || fail "calibrate from the rim circle left views out"
  grep -q "model: pinhole" "$work/cal_rim/sensor.yaml" && grep -q "profile: even_asphere" "$work/cal_rim/sensor.yaml" && pass ||
    fail "calibrate from the rim circle: sensor.yaml is not a pinhole even asphere"
  python3 - "$work/cal_rim/calibration.json" "$work/diff_rim/diff.json" <<'PYRIM' && pass || fail "calibrate from the rim circle: the lens not chosen by default as measured"
import json, sys
cal, diff = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
lens, profile, tangential = cal["lens_choice"], cal["profile_choice"], cal["tangential_choice"]
ortho, pinhole = lens["held_out_rms_px"]
assert lens["chosen"] == "pinhole" and ortho is not None and pinhole < 0.5 * ortho, lens
polynomial, conic = profile["held_out_rms_px"]
assert profile["chosen"] == "even_asphere" and polynomial == pinhole and conic < 0.5 * polynomial, profile
held, fitted = tangential["held_out_rms_px"]
assert tangential["chosen"] == "held" and held == conic, tangential
assert lens["held_out_corners"] == profile["held_out_corners"] == tangential["held_out_corners"] == 1080, (lens, tangential)
assert diff["aligned"] and diff["diff_rms_px"] < 0.15, diff
PYRIM
else
  fail "calibrate from the rim circle exited $?"
fi
# A perspective camera in front of an unknown mirror, the lens, the mirror family and p1,
# p2 chosen by held-out folds (the defaults without a guess): these renders' camera is a
# pinhole, which the orthographic start approximates by a tilt. On the 12 views at 4-14
# mirror radii, from their raw corners, measured (2026-11-30): held out 0.305 px through the
# pinhole against 2.562 px through the orthographic lens; through the pinhole the even
# asphere (the mirror is a sphere) 0.158 px against the polynomial's 0.305; the fit 0.097
# px RMS, and 0.095 px RMS from the true sensor over the corners' annulus at 300 mm (the
# polynomial, kept until 2026-11-30: 0.126 px RMS, 0.204 px from the truth; the orthographic
# fit: 1.58 px). The render's lens has no tangential distortion, and --tangential auto holds
# p1, p2 (held out 0.1583 px held, 0.1615 fitted).
mixed=$source_dir/datasets-synthetic/rendered/ohte-sph-misaligned-mixed
if "$omnical" -q detect --target "$grid" --images "$mixed" --out "$work/det_mixed.json" &&
  "$omnical" -q calibrate --target "$grid" --detections "$work/det_mixed.json" --out "$work/cal_lens" 2>/dev/null &&
  "$omnical" -q diff "$mixed/sensor.yaml" "$work/cal_lens" --distance-mm 300 --field "$work/det_mixed.json" \
    --out "$work/diff_lens" >/dev/null; then
  python3 - "$work/cal_lens" "$work/diff_lens" <<'PYLENS' && pass || fail "calibrate without a guess: the pinhole not chosen by default, or not better"
import json, sys
cal, diff = json.load(open(sys.argv[1] + "/calibration.json")), json.load(open(sys.argv[2] + "/diff.json"))
choice = cal["lens_choice"]
assert choice["candidates"] == ["orthographic", "pinhole"] and choice["chosen"] == "pinhole", choice
ortho, pinhole = choice["held_out_rms_px"]
assert pinhole < 0.25 * ortho, choice
assert cal["start"] == ("rim circle, even_asphere mirror (chosen by held-out folds), pinhole lens (chosen by held-out "
                        "folds)"), cal["start"]
profile = cal["profile_choice"]
assert profile["candidates"] == ["polynomial", "even_asphere"] and profile["chosen"] == "even_asphere", profile
assert profile["held_out_rms_px"][0] == pinhole and profile["held_out_rms_px"][1] < 0.7 * pinhole, (profile, choice)
# A conic has no free-form terms: m, decenter, k1, k2 are fitted (a free polynomial holds them).
assert cal["fixed_blocks"] == ["tangential"], cal["fixed_blocks"]
assert cal["rms_px"] < 0.15 and diff["aligned"] and diff["diff_rms_px"] < 0.15, (cal["rms_px"], diff)
tangential = cal["tangential_choice"]
assert tangential["candidates"] == ["held", "fitted"] and tangential["chosen"] == "held", tangential
conic = profile["held_out_rms_px"][1]
assert tangential["held_out_rms_px"][0] == conic and tangential["folds"] == choice["folds"], (tangential, choice)
PYLENS
  grep -q "model: pinhole" "$work/cal_lens/sensor.yaml" && pass || fail "calibrate without a guess: sensor.yaml has no pinhole"
else
  fail "calibrate without a guess (the mixed renders) exited $?"
fi
# An ideal paraboloid cannot bend to these views. Through the pinhole (m, k1, k2 free) 4 of
# 5 fold fits fold their distortion: no valid sensor, so the pinhole fails (before that
# rule it was chosen at 3.58 px held out, and its sensor.yaml did not load). The
# orthographic lens is chosen, poor as it is (held out 11.2 px; until held-out views were
# posed through the fold's whole valid mirror it failed too, and was kept with the warning
# lens_not_chosen). --tangential auto then fits no p1, p2 (said), nor do the folds of
# --holdout-folds (which refused them once).
if "$omnical" -q calibrate --target "$grid" --detections "$work/det.json" --lens auto --profile paraboloid \
  --tangential auto --holdout-folds 4 --out "$work/cal_lens_none" 2>"$work/lens_none.err"; then
  ! grep -q "warning: neither lens" "$work/lens_none.err" && grep -q "warning: tangential auto: the orthographic lens was chosen" "$work/lens_none.err" &&
    [ "$(json "$work/cal_lens_none/calibration.json" start)" = "rim circle, paraboloid mirror, orthographic lens (chosen by held-out folds)" ] &&
    python3 -c "import json,sys; d=json.load(open(sys.argv[1])); c=d['lens_choice']; s=c['held_out_rms_px']; sys.exit(0 if s[0] > 1 and s[1] is None and c['chosen'] == 'orthographic' and 'tangential_choice' not in d else 1)" \
      "$work/cal_lens_none/calibration.json" && pass || fail "calibrate --lens auto, the pinhole no valid sensor: $(cat "$work/lens_none.err")"
else
  fail "calibrate --lens auto --profile paraboloid exited $?"
fi
# Data that cannot determine what is asked: six views all 37-43 mirror radii away with the
# sphere's radius free, and a solver cut to 10 iterations. The fit is written, with the
# reasons on stderr and in calibration.json (issue 8).
far=$source_dir/datasets-synthetic/rendered/ohte-sph-far
if "$omnical" -q detect --target "$targets/aprilgrid-6x6-88mm.yaml" --images "$far" --out "$work/det_far.json" &&
  "$omnical" -q calibrate --target "$targets/aprilgrid-6x6-88mm.yaml" --detections "$work/det_far.json" \
    --sensor "$sensors/ohte-sph.yaml" --max-iterations 10 --out "$work/cal_far" 2>"$work/far.err"; then
  for reason in "all targets are at one distance" "while the mirror shape is free" "A_mm is weakly determined" \
    "did not converge"; do
    grep -qF "$reason" "$work/far.err" && grep -qF "$reason" "$work/cal_far/calibration.json" && pass ||
      fail "calibrate on one distance: no warning '$reason': $(cat "$work/far.err")"
  done
else
  fail "calibrate on one distance exited $?"
fi
# --profile converts the guess (a sphere design fitted as a free polynomial mirror).
"$omnical" -q calibrate --target "$grid" --detections "$work/det.json" --sensor "$guess" --profile polynomial --out "$work/cal_poly" 2>/dev/null &&
  grep -q "profile: polynomial" "$work/cal_poly/sensor.yaml" && near "$(json "$work/cal_poly/calibration.json" rms_px)" 0.15 0.15 "calibrate --profile polynomial RMS (px)" ||
  fail "calibrate --profile polynomial"
blank=$work/blank && mkdir -p "$blank"
for k in 1 2 3; do { printf 'P5\n64 48\n255\n'; head -c 3072 /dev/zero; } >"$blank/b$k.pgm"; done
calibrate_start_error() {
  local name=$1 expected=$2
  shift 2
  rm -rf "$work/cal_bad"
  expect_error "$name" "$expected" -- calibrate --out "$work/cal_bad" "$@"
  [ ! -e "$work/cal_bad" ] && pass || fail "$name: left $work/cal_bad behind"
}
calibrate_start_error calibrate_both_sources "give either --images" --target "$grid" --images "$rendered" --detections "$work/det.json"
calibrate_start_error calibrate_no_source "give either --images" --target "$grid"
calibrate_start_error calibrate_no_rim "no mirror rim circle found" --target "$grid" --images "$blank"
calibrate_start_error calibrate_lens_with_guess "lens: the guess has its lens (pinhole)" --target "$grid" --detections "$work/det.json" --sensor "$guess" --lens pinhole
calibrate_start_error calibrate_tangential_orthographic "tangential: the orthographic lens has no tangential distortion (p1, p2 are a pinhole's); give lens pinhole or auto" --target "$grid" --detections "$work/det.json" --lens orthographic --tangential on
calibrate_start_error calibrate_relief_without_warp "board_relief: on fits the relief on top of the board's warp, which board_warp off holds flat" --target "$grid" --detections "$work/det.json" --board-relief on --no-board-warp
calibrate_start_error calibrate_hyperboloid_needs_guess "a hyperboloid needs a guess" --target "$grid" --detections "$work/det.json" --profile hyperboloid
# A corrupt image is reported and skipped; the others are detected.
mkdir -p "$work/mixed" && cp "$rendered/near-front.png" "$rendered/near000.png" "$work/mixed/" && printf 'not a png' >"$work/mixed/broken.png"
"$omnical" -q detect --target "$grid" --images "$work/mixed" --out "$work/mixed.json" 2>"$work/stderr" &&
  grep -q "broken.png: cannot read the image, skipped" "$work/stderr" &&
  [ "$(python3 -c "import json,sys; print(len(json.load(open(sys.argv[1]))['images']))" "$work/mixed.json")" = 2 ] && pass ||
  fail "detect with a corrupt image"

summary cli_test
