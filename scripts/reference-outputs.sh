#!/usr/bin/env bash
# The outputs of the jobs on the bundled data, for comparing two builds of omnical
# (scripts/compare-outputs.py): calibrate each bundled rendered aprilgrid set from its
# committed images (and the checkerboard set), remap/parallax/export-central/characterize
# on the bundled sensors, design on the bundled design specs.
# Usage: scripts/reference-outputs.sh OMNICAL_BINARY OUT_DIR
set -euo pipefail
omnical=$1
out=$2
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
data=$root/datasets-synthetic
mkdir -p "$out"
run() { "$omnical" --quiet "$@" >/dev/null 2>>"$out/stderr.txt" || echo "FAILED ($?): $*" >>"$out/stderr.txt"; }
for set in ohte-sph-near ohte-sph-misaligned-near ohte-edi-near ohte-svp-near; do
  sensor=$(sed -n 's/^sensor: \.\.\/sensors\/\(.*\)$/\1/p' "$data/scenes/$set.yaml")
  guess=$data/sensors/$sensor
  [ "$set" = ohte-sph-misaligned-near ] && guess=$data/sensors/ohte-sph-misaligned-guess.yaml
  run calibrate --target "$data/targets/aprilgrid-6x6-30mm.yaml" --images "$data/rendered/$set" --sensor "$guess" \
    --threads 2 --out "$out/calibrate-$set"
done
run calibrate --target "$data/targets/checkerboard-8x6-30mm.yaml" --images "$data/rendered/ohte-sph-checkerboard-near" \
  --sensor "$data/sensors/ohte-sph.yaml" --threads 2 --out "$out/calibrate-checkerboard"
run detect --target "$data/targets/aprilgrid-6x6-30mm.yaml" --images "$data/rendered/ohte-sph-misaligned-near" \
  --sensor "$data/sensors/ohte-sph-misaligned-guess.yaml" --threads 2 --out "$out/detections-misaligned.json"
run calibrate --target "$data/targets/aprilgrid-6x6-30mm.yaml" --detections "$out/detections-misaligned.json" \
  --sensor "$data/sensors/ohte-sph-misaligned-guess.yaml" --tolerance m_mm=2,decenter_mm=1,tilt_deg=1,principal_point_px=10 \
  --distance-n 7 --leave-one-out --out "$out/calibrate-detections"
for sensor in ohte-sph ohte-edi ohte-svp ohte-sph-misaligned; do
  s=$data/sensors/$sensor.yaml
  run remap --sensor "$s" --view panorama --n 7 --size 512x128 --format opencv,ffmpeg,npy --out "$out/remap-$sensor-pano"
  run remap --sensor "$s" --view perspective --infinity --size 160x120 --format npy --out "$out/remap-$sensor-persp"
  run remap --sensor "$s" --view equiangular --distance-mm 500 --surface cylinder --size 200x200 --format npy --out "$out/remap-$sensor-eq"
  run parallax --sensor "$s" --n 7 --out "$out/parallax-$sensor"
  run parallax --maps "$out/remap-$sensor-pano" --out "$out/parallax-maps-$sensor"
  run characterize --sensor "$s" --out "$out/characterize-$sensor"
  run export-central --sensor "$s" --model mei --n 7 --out "$out/central-$sensor"
  run unwarp --maps "$out/remap-$sensor-pano" --input "$(ls "$data"/rendered/$sensor-near/*.png | head -1)" --out "$out/unwarp-$sensor.png"
done
for design in gaechter-uniform gaechter-logpolar; do
  run design ode --spec "$data/designs/$design.yaml" --out "$out/design-$design"
done

run design fit --profile sphere --rim-omega 135 --rim-theta 12 --out "$out/design-fit-sph"
run design fit --profile hyperboloid --characteristic svp --out "$out/design-fit-svp"
run design fit --profile polynomial --characteristic equidistant --compare "$data/sensors/ohte-edi.yaml" --out "$out/design-fit-edi"
run render --scene "$data/scenes/ohte-sph-misaligned-near.yaml" --out "$out/render-misaligned"
# The real dev set (../shared/real-data, beside the checkout), when present: from the
# images alone and from the two hand-made guesses.
real=$root/../shared/real-data/mei-parabolic
if [ -d "$real" ]; then
  board=$root/tests/data/mei-parabolic-checkerboard.yaml
  run calibrate --target "$board" --images "$real" --threads 2 --out "$out/calibrate-real"
  run calibrate --target "$board" --images "$real" --sensor "$root/tests/data/mei-parabolic-guess.yaml" --threads 2 --out "$out/calibrate-real-paraboloid"
  run calibrate --target "$board" --images "$real" --sensor "$root/tests/data/mei-parabolic-polynomial-guess.yaml" --threads 2 --out "$out/calibrate-real-polynomial"
fi
echo "reference outputs in $out"
