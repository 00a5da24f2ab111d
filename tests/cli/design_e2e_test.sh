#!/usr/bin/env bash
# A designed mirror end to end from the command line (issue 7): `design ode` makes the
# seed's log-polar mirror (a tabulated profile); the script builds an "as-built" sensor from
# it (the assembly errors a workshop leaves: m + 1.2 mm, tilt 0.5 / -0.4 deg, decenter
# 0.3 / 0.2 mm, focal length + 0.5 %, principal point off by 2 px), renders 12 aprilgrid
# views through it, calibrates from the design as the only guess, and unwarps a view.
# Checked: the fit (RMS < 0.1 px, m within 0.1 %, every free parameter within 3 standard
# deviations of the truth) and the panorama table at the design distance (2 m) built from
# the calibration against the one built from the truth: < 0.25 px everywhere, where the
# uncalibrated design is off by pixels (so the check can fail).
# Usage: design_e2e_test.sh OMNICAL_BINARY SOURCE_DIR MAPCHECK_BINARY
set -u
omnical=$1
source_dir=$(cd "$2" && pwd)
mapcheck=$3
data=$source_dir/datasets-synthetic
source "$(dirname "${BASH_SOURCE[0]}")/harness.sh"

"$omnical" -q design ode --spec "$data/designs/gaechter-logpolar.yaml" --image-size 800 --out "$work/design" ||
  { echo "FAIL: design ode"; exit 1; }
sed -e 's/fx: [0-9.e+-]*, fy: [0-9.e+-]*, cx: [0-9.e+-]*, cy: [0-9.e+-]*/fx: 2760.6, fy: 2760.6, cx: 401.8, cy: 397.9/' \
  -e 's/m: 190, tilt_deg: \[0, 0\], decenter_mm: \[0, 0\]/m: 191.2, tilt_deg: [0.5, -0.4], decenter_mm: [0.3, 0.2]/' \
  "$work/design/sensor.yaml" >"$work/design/as-built.yaml"
grep -q "m: 191.2" "$work/design/as-built.yaml" && grep -q "fx: 2760.6" "$work/design/as-built.yaml" ||
  { echo "FAIL: the design's sensor.yaml changed form; the as-built edit did not apply"; exit 1; }
# Boards at 10-24 mirror radii (0.3-0.7 m) over the design's field (Omega 25-96 deg).
cat >"$work/scene.yaml" <<EOF
sensor: $work/design/as-built.yaml
render: { samples_per_pixel: 9, noise_sigma: 0, vignetting: 0.15, seed: 3 }
environment: { type: room, half_size_mm: 2500, tile_mm: 250, levels: [0.25, 0.55] }
targets:
  board: $data/targets/aprilgrid-6x6-88mm.yaml
random_views: { count: 12, target: board, omega_deg: [32, 90], azimuth_deg: [0, 360], distance_n: [10, 24],
                tilt_deg: [0, 35], roll_deg: [-45, 45], seed: 5, prefix: view }
EOF
"$omnical" -q render --scene "$work/scene.yaml" --out "$work/render" || { echo "FAIL: render"; exit 1; }
"$omnical" -q calibrate --target "$data/targets/aprilgrid-6x6-88mm.yaml" --images "$work/render" \
  --sensor "$work/design/sensor.yaml" --fix distortion --out "$work/cal" || { echo "FAIL: calibrate exited $?"; exit 1; }

python3 - "$work/design/as-built.yaml" "$work/cal/calibration.json" <<'PY' && pass || fail "calibration of the designed mirror"
import json, re, sys
text = open(sys.argv[1]).read()
def scalar(key):
    return float(re.search(r"\b" + key + r":\s*([-+0-9.eE]+)", text).group(1))
def pair(key):
    return [float(x) for x in re.search(r"\b" + key + r":\s*\[([^\]]*)\]", text).group(1).split(",")]
tilt, decenter = pair("tilt_deg"), pair("decenter_mm")
truth = {"fx_px": scalar("fx"), "fy_px": scalar("fy"), "cx_px": scalar("cx"), "cy_px": scalar("cy"), "m_mm": scalar("m"),
         "tilt_x_deg": tilt[0], "tilt_y_deg": tilt[1], "decenter_x_mm": decenter[0], "decenter_y_mm": decenter[1]}
result = json.load(open(sys.argv[2]))
p = result["parameters"]
ok = result["converged"] and result["rms_px"] < 0.1
print("%d corners, rms %.4f px" % (result["observations"], result["rms_px"]))
for name, value in truth.items():
    e = p[name]
    if e["fixed"]: continue
    dev = (e["value"] - value) / e["std"]
    print("%-14s %.6g +- %.3g vs truth %.6g: %.2f std" % (name, e["value"], e["std"], value, dev))
    ok = ok and abs(dev) < 3.0
rel_m = abs(p["m_mm"]["value"] - truth["m_mm"]) / truth["m_mm"]
print("m within %.4f %%" % (100 * rel_m))
sys.exit(0 if ok and rel_m < 1e-3 else 1)
PY

# Unwarping: the panorama at the design distance from the calibrated sensor, the truth and
# the uncalibrated design, compared omni pixel for omni pixel.
for s in cal/sensor.yaml design/as-built.yaml design/sensor.yaml; do
  "$omnical" -q remap --sensor "$work/$s" --view panorama --size 720x180 --elevation-deg 5,-60 --distance-mm 2000 \
    --format opencv --out "$work/maps-${s//\//-}" || fail "remap with $s"
done
read -r calibrated_max calibrated_rms common flipped < <("$mapcheck" compare "$work/maps-cal-sensor.yaml/maps.yml.gz" \
  "$work/maps-design-as-built.yaml/maps.yml.gz")
read -r design_max design_rms _ _ < <("$mapcheck" compare "$work/maps-design-sensor.yaml/maps.yml.gz" \
  "$work/maps-design-as-built.yaml/maps.yml.gz")
echo "panorama vs the truth's: calibrated max $calibrated_max px (rms $calibrated_rms) over $common pixels, $flipped flip" \
  "validity; uncalibrated design max $design_max px (rms $design_rms)"
check awk -v e="$calibrated_max" 'BEGIN { exit !(e < 0.25) }'
check awk -v e="$design_max" 'BEGIN { exit !(e > 2.0) }'
check awk -v f="$flipped" -v c="$common" 'BEGIN { exit !(f < 0.001 * c) }'
"$omnical" -q unwarp --maps "$work/maps-cal-sensor.yaml" --input "$work/render/view000.png" --out "$work/pano.png" &&
  "$mapcheck" same-size "$work/pano.png" 720 180 && pass || fail "unwarp of a rendered view"
summary design_e2e_test
