#!/usr/bin/env bash
# A decoy board among the images: the realistic aprilgrid render's 12 views plus one of a
# board 4 times the size (same tags) 4 times as far, rendered here. calibrate --images must
# refuse it (the board-size screen) before the second detection pass refines the corners
# through the first fit, so that the result is the one without the decoy's image: every
# free parameter within 0.05 of its std (measured: identical). Screened only after that
# pass, as before, fx and m ended 0.92 and 0.77 std from it. The decoy's corners stay in
# detections.json (every corner found is written). The calibration without the decoy is
# cli.realistic_render's, of the same images with the same options (a CTest fixture: it
# runs first and keeps it in WITHOUT_DIR), so the 12 views are not calibrated twice.
# Usage: decoy_images_test.sh OMNICAL_BINARY SOURCE_DIR WITHOUT_DIR
set -u
omnical=$1
source_dir=$(cd "$2" && pwd)
without=${3:?usage: decoy_images_test.sh OMNICAL_BINARY SOURCE_DIR WITHOUT_DIR}
data=$source_dir/datasets-synthetic
source "$(dirname "${BASH_SOURCE[0]}")/harness.sh"

sed 's/tagSize: 0.030/tagSize: 0.120/' "$data/targets/aprilgrid-6x6-30mm.yaml" >"$work/giant.yaml"
cat >"$work/scene.yaml" <<EOF
sensor: $data/sensors/ohte-sph-misaligned.yaml
render: { samples_per_pixel: 16, noise_sigma: 3, blur_sigma_px: 0.8, vignetting: 0.35, jpeg_quality: 85, colour: true, seed: 7 }
environment: { type: room, half_size_mm: 2500, tile_mm: 250, levels: [0.25, 0.55] }
targets:
  giant: { spec: $work/giant.yaml, warp_mm: [3, -1.5] }
views:
  - { name: giant, giant: { omega_deg: 75, azimuth_deg: 150, distance_n: 28, tilt_deg: [10, 5], roll_deg: 15 } }
EOF
"$omnical" -q render --scene "$work/scene.yaml" --out "$work/render" || { echo "FAIL: render exited $?"; exit 1; }
[ "$without/calibration.json" -nt "$omnical" ] ||
  { echo "FAIL: no calibration without the decoy in $without newer than $omnical (cli.realistic_render keeps it)"; exit 1; }
mkdir -p "$work/with"
cp "$data"/rendered/realistic-aprilgrid/*.jpg "$work/render/giant.jpg" "$work/with/"
# The options of tests/cli/realistic_render_test.sh's calibration.
"$omnical" -q calibrate --target "$data/targets/aprilgrid-6x6-30mm.yaml" --images "$work/with" \
  --sensor "$data/sensors/ohte-sph-misaligned-guess.yaml" --board-warp --threads 2 --out "$work/cal_with" 2>/dev/null ||
  { echo "FAIL: calibrate (with the decoy) exited $?"; exit 1; }

python3 - "$work/cal_with" "$without" <<'PY'
import json, os, sys
with_dir, without_dir = sys.argv[1], sys.argv[2]
a = json.load(open(os.path.join(with_dir, "calibration.json")))
b = json.load(open(os.path.join(without_dir, "calibration.json")))
failed = []
def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok: failed.append(what)

refused = [image for image in a.get("views_left_out", {}) if image.endswith("giant.jpg")]
check(len(refused) == 1, "the decoy refused: %s" % a.get("views_left_out", {}))
check(a["detection_passes"] == 2, "two detection passes (%d)" % a["detection_passes"])
for name, p in b["parameters"].items():
    if p["fixed"]: continue
    z = (a["parameters"][name]["value"] - p["value"]) / p["std"]
    check(abs(z) <= 0.05, "%s %.6g with the decoy, %.6g without: %.3f std (within 0.05)" % (name, a["parameters"][name]["value"], p["value"], z))
detections = json.load(open(os.path.join(with_dir, "detections.json")))
giant = [len(i["corners"]) for i in detections["images"] if i["image"].endswith("giant.jpg")]
check(giant and giant[0] >= 100, "the decoy's corners in detections.json (%s)" % giant)
sys.exit(1 if failed else 0)
PY
