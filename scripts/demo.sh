#!/usr/bin/env bash
# Installs what is missing, builds omnical in Release and runs the main job on the bundled
# synthetic data. Today: (0) the main job on a misaligned spherical mirror: render 8 views
# with ground truth, detect the aprilgrid, calibrate from the design guess, parallax report
# of the result, remap tables exact at n = 7 exported for OpenCV/ffmpeg/NumPy, a view
# unwarped through them and their error at other distances; then for each of the seed paper's three mirrors, (1) the sensor model:
# unproject a pixel grid to rays, put objects 7 mirror radii away along them (the paper's
# near case) and project them back exactly; (2) the paper's optics evaluation
# (characterize); (3) the parallax report for objects at n = 7 (parallax).
# Output: demo-out/ (or $1).
set -euo pipefail
omnical_build_kind=demo
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
prepare_demo_build
out=${1:-$omnical_root/demo-out}
mkdir -p "$out"
# The main job on a misaligned sensor: render its near-target views, detect the tags,
# calibrate from the nominal design guess, then the parallax report of the calibrated sensor.
"$omnical" render --scene "$omnical_root/datasets-synthetic/scenes/ohte-sph-misaligned-near.yaml" --out "$out/render"
"$omnical" detect --target "$omnical_root/datasets-synthetic/targets/aprilgrid-6x6-30mm.yaml" --images "$out/render" \
  --sensor "$omnical_root/datasets-synthetic/sensors/ohte-sph-misaligned-guess.yaml" --out "$out/detections.json"
# The design's tolerances as weak priors, and the error predicted where the remap tables
# below are exact (n = 7): calibration.json and report/predicted_error_*.png.
"$omnical" calibrate --target "$omnical_root/datasets-synthetic/targets/aprilgrid-6x6-30mm.yaml" \
  --detections "$out/detections.json" --sensor "$omnical_root/datasets-synthetic/sensors/ohte-sph-misaligned-guess.yaml" \
  --tolerance m_mm=2,decenter_mm=1,tilt_deg=1,principal_point_px=10 --distance-n 7 --out "$out/calibration"
"$omnical" parallax --sensor "$out/calibration/sensor.yaml" --n 7 --out "$out/calibration/parallax-n7"
# Remap tables from the calibrated sensor, exact for objects 7 rim radii away, for OpenCV,
# ffmpeg and NumPy; one rendered image unwarped through them; their error elsewhere.
"$omnical" remap --sensor "$out/calibration/sensor.yaml" --view panorama --n 7 --format opencv,ffmpeg,npy \
  --out "$out/calibration/remap-n7"
"$omnical" unwarp --maps "$out/calibration/remap-n7" \
  --input "$out/render/near-front.png" \
  --out "$out/calibration/remap-n7/near-front-panorama.png"
"$omnical" parallax --maps "$out/calibration/remap-n7" --out "$out/calibration/remap-n7/error"
# The best-fit central (Mei) model for central-only tools, with its error over the field.
"$omnical" export-central --sensor "$out/calibration/sensor.yaml" --model mei --n 7 --out "$out/calibration/central-mei"

for mirror in ohte-sph ohte-edi ohte-svp; do
  sensor="$omnical_root/datasets-synthetic/sensors/$mirror.yaml"
  "$omnical" unproject --sensor "$sensor" --pixels "$omnical_root/datasets-synthetic/pixels/grid-25px.csv" \
    --out "$out/$mirror-rays.csv"
  # Objects 7 rim radii (7 x 43.9 mm) from the mirror along each ray.
  awk -F, 'NR > 1 && $7 == "ok" { d = 307.3; printf "%.17g,%.17g,%.17g\n", $1 + d*$4, $2 + d*$5, $3 + d*$6 }' \
    "$out/$mirror-rays.csv" >"$out/$mirror-points-n7.csv"
  "$omnical" project --sensor "$sensor" --points "$out/$mirror-points-n7.csv" --out "$out/$mirror-pixels-n7.csv"
  rays=$(tail -n +2 "$out/$mirror-rays.csv" | grep -c ',ok$' || true)
  back=$(tail -n +2 "$out/$mirror-pixels-n7.csv" | grep -c ',ok$' || true)
  # Largest distance between a grid pixel and the pixel its object projects back to.
  worst=$(paste -d, <(tail -n +2 "$omnical_root/datasets-synthetic/pixels/grid-25px.csv") <(tail -n +2 "$out/$mirror-rays.csv") |
    awk -F, '$9 == "ok" { print $1 "," $2 }' | paste -d, - <(tail -n +2 "$out/$mirror-pixels-n7.csv") |
    awk -F, '{ du = $1 - $3; dv = $2 - $4; e = sqrt(du*du + dv*dv); if (e > w) w = e } END { printf "%.2g", w }')
  echo "$mirror: $rays pixels see the mirror; their objects at n = 7 project back within $worst px ($back ok)"
  "$omnical" characterize --sensor "$sensor" --out "$out/$mirror-characterize"
  "$omnical" parallax --sensor "$sensor" --n 7 --out "$out/$mirror-parallax-n7"
done
# The Python module from the build tree (docs/python.md): the calibrated sensor projects the
# same point as the CLI.
if [ -d "$build_dir/python/omnical" ]; then
  PYTHONPATH="$build_dir/python" "$(command -v /usr/bin/python3 || command -v python3)" - "$out/calibration/sensor.yaml" <<'PY'
import sys
import omnical
sensor = omnical.Sensor.load(sys.argv[1])
pixels, status = sensor.project([[400.0, -150.0, 60.0]])
print(f"python: omnical {omnical.__version__}: {sensor!r} projects (400, -150, 60) mm to "
      f"({pixels[0, 0]:.3f}, {pixels[0, 1]:.3f}) px ({omnical.status_name(status[0])})")
PY
  echo "python: PYTHONPATH=$build_dir/python python3 tools/python/examples/calibrate_and_unwarp.py example-out"
fi
echo "demo outputs in $out"
