#!/usr/bin/env bash
# Bad input against every subcommand (issue 8), run as a test and written as a Markdown
# table: missing, empty and corrupt files, truncated PNG, non-image, 16-bit and colour
# images, wrong target specs, NaN / inf / huge / negative numbers, an output directory that
# cannot be created, and a disk that fills up (a file-size limit: writes fail with EFBIG,
# as on a full disk). Every row must end with exit code 2, one error line on stderr (after
# any "omnical: warning:" lines, e.g. images skipped), within 60 s,
# and leave nothing at its output path. Rows that accept the input (exit 0) are allowed
# only where marked "accepted" (16-bit and colour images are converted, by design), and
# required where marked "processed" (the input is valid but for what the row names).
# Usage: bad_input_table.sh OMNICAL_BINARY SOURCE_DIR TABLE.md
set -u
omnical=$1
source_dir=$(cd "$2" && pwd)
table=$3
data=$source_dir/datasets-synthetic
source "$(dirname "${BASH_SOURCE[0]}")/harness.sh"

sensor=$data/sensors/ohte-sph.yaml
grid=$data/targets/aprilgrid-6x6-30mm.yaml
rendered=$data/rendered/ohte-sph-misaligned-near
omni=$rendered/near000.png
guess=$data/sensors/ohte-sph-misaligned-guess.yaml

# Fixtures.
f=$work/fixtures
mkdir -p "$f"
: >"$f/empty.yaml"
: >"$f/empty.csv"
printf 'camera: { model: pinhole\nmirror: [\n' >"$f/corrupt.yaml"
sed 's/fx: [0-9.]*/fx: .nan/' "$sensor" >"$f/sensor-nan.yaml"
sed 's/A: [0-9.]*/A: .inf/' "$sensor" >"$f/sensor-inf.yaml"
sed 's/{ m: [0-9.]*/{ m: 1e308/' "$sensor" >"$f/sensor-huge.yaml"
sed 's/image_size: \[1000, 1000\]/image_size: [-1000, 1000]/' "$sensor" >"$f/sensor-negative.yaml"
sed 's/A: [0-9.]*/A: 20/' "$sensor" >"$f/sensor-domain.yaml"  # rim 43.9 mm beyond a 20 mm sphere
sed 's/target_type: .*/target_type: hexgrid/' "$grid" >"$f/target-type.yaml"
sed 's/tagSize: .*/tagSize: -0.03/' "$grid" >"$f/target-negative.yaml"
printf 'u,v\n500,nan\n' >"$f/pixels-nan.csv"
printf 'X,Y,Z\n1e400,0,100\n' >"$f/points-huge.csv"
printf 'X,Y,Z\n100,0\n' >"$f/points-short.csv"
printf 'X,Y,Z\n300,40,100\n' >"$f/points.csv"
mkdir -p "$f/truncated" "$f/notimage" "$f/deep" "$f/colour" "$f/no-images" "$f/strip"
head -c 2000 "$omni" >"$f/truncated/near000.png"
echo "not an image" >"$f/notimage/near000.png"
ffmpeg -loglevel error -y -i "$omni" -pix_fmt gray16be "$f/deep/near000.png"
ffmpeg -loglevel error -y -i "$omni" -pix_fmt rgb24 "$f/colour/near000.png"
ffmpeg -loglevel error -y -i "$omni" -vf scale=64:2 -pix_fmt gray "$f/strip/near000.png"  # AprilTag segfaulted on it
head -c 300 "$omni" >"$f/truncated.png"
"$omnical" -q remap --sensor "$sensor" --view panorama --size 64x16 --infinity --format opencv --out "$f/maps"
# For the image the 16-bit and colour inputs were made from (a 1040 px render of the
# misaligned sphere): the unwarp rows on them test the conversion, not the size check.
"$omnical" -q remap --sensor "$data/sensors/ohte-sph-misaligned.yaml" --view panorama --size 64x16 --infinity \
  --format opencv --out "$f/maps-1040"
mkdir -p "$f/maps-corrupt" && cp "$f/maps/maps.yml.gz" "$f/maps-corrupt/" && echo '{"view": 3' >"$f/maps-corrupt/maps.json"
sed "s#\\.\\./#$data/#; s/samples_per_pixel: [0-9]*/samples_per_pixel: -4/" "$data/scenes/ohte-sph-far.yaml" >"$f/scene-negative.yaml"
sed "s#\\.\\./#$data/#; s/distance_n: \[37, 43\]/distance_n: [.nan, 43]/" "$data/scenes/ohte-sph-far.yaml" >"$f/scene-nan.yaml"
# One view, one sample per pixel: quick even under the sanitizers.
sed "s#\.\./#$data/#; s/samples_per_pixel: [0-9]*/samples_per_pixel: 1/; s/count: 6/count: 1/" "$data/scenes/ohte-sph-far.yaml" >"$f/scene-small.yaml"
sed "s#\.\./#$data/#; s/warp_mm: \[3, 1\]/warp_mm: [3]/" "$data/scenes/realistic-checkerboard.yaml" >"$f/scene-warp.yaml"
sed "s#\.\./#$data/#; s/jpeg_quality: 85/jpeg_quality: 120/" "$data/scenes/realistic-checkerboard.yaml" >"$f/scene-jpeg.yaml"
printf '{"target": "%s", "image_size": [1040, 1040], "images": [{"image": "a.png", "corners": [{"id": 1, "pixel": [1e999, 2]}]}]}' \
  "$grid" >"$f/detections-huge.json"
# Finite but absurd (its squared residual overflowed and crashed the report), and ids that
# are not whole numbers (read as 2 and 1 before).
sed 's/1e999/1e300/' "$f/detections-huge.json" >"$f/detections-far.json"
# Corners found on a 50 mm board, calibrated as the 30 mm one (exit 0, a mirror 13 % too big, before).
sed 's/"image_size"/"target_description": "aprilgrid 6 x 6 tag36h11 from id 0, 50 mm tags, spacing 0.3", "image_size"/; s/1e999/100/' \
  "$f/detections-huge.json" >"$f/detections-other-board.json"
sed 's/"id": 1/"id": 2.5/; s/1e999/100/' "$f/detections-huge.json" >"$f/detections-id-fraction.json"
sed 's/"id": 1/"id": true/; s/1e999/100/' "$f/detections-huge.json" >"$f/detections-id-bool.json"
sed 's/1e999/100/' "$f/detections-huge.json" >"$f/detections-one.json"
sed "s#\.\./#$data/#; s#prefix: far#prefix: ../far#" "$data/scenes/ohte-sph-far.yaml" >"$f/scene-escape.yaml"
printf 'x_mm,z_mm\n0,0\n1,0.1\n0.5,0.2\n2,0.3\n' >"$f/profile-back.csv"
printf 'camera: { model: pinhole, image_size: [1000, 1000], fx: 2352, fy: 2352, cx: 499.5, cy: 499.5, k1: 0, k2: 0 }\nmirror: { profile: tabulated, rim_radius: 2, table: profile-back.csv }\npose: { m: 180, tilt_deg: [0, 0], decenter_mm: [0, 0] }\n' >"$f/sensor-table.yaml"
readonly_dir=/proc/omnical-cannot-write  # cannot be created, even as root

rows=()
bad=0
runner=("$omnical")
# row SUBCOMMAND "INPUT" OUT EXPECT -- ARGS: OUT is the output path that must not exist
# afterwards ("-": stdout only); EXPECT is "error" (exit 2), "write-error" (exit 2 when a
# write fails: no temporary file may stay; files completed before the failure may) or
# "accepted" (exit 0 allowed) or "processed" (exit 0 required).
row() {
  local sub=$1 input=$2 out=$3 expect=$4
  shift 5
  [ "$out" != - ] && rm -rf "$out"
  local start=$SECONDS
  timeout 60 "${runner[@]}" "$@" >"$work/stdout" 2>"$work/stderr"
  local code=$? verdict=ok message
  message=$(grep -v '^omnical: warning: ' "$work/stderr" | head -1 | head -c 300 | sed "s#$work/##g; s#$source_dir/##g; s#|#/#g")
  if [ "$code" -eq 124 ]; then verdict="HANG"
  elif [ "$code" -gt 128 ]; then verdict="CRASH (signal $((code - 128)))"
  elif [ "$expect" = accepted ] || [ "$expect" = processed ] && [ "$code" -eq 0 ]; then verdict="accepted"; message="(processed)"
  elif [ "$expect" = processed ]; then verdict="exit $code, expected 0"
  elif [ "$code" -ne 2 ]; then verdict="exit $code, expected 2"
  elif [ "$(grep -vc '^omnical: warning: ' "$work/stderr")" -ne 1 ]; then verdict="$(wc -l <"$work/stderr") stderr lines"
  elif [ "$expect" = write-error ] && [ -n "$(find "$out" \( -name '*.tmp*' -o -name '.tmp*' \) 2>/dev/null | head -1)" ]; then
    verdict="left a temporary file"
  elif [ "$expect" != write-error ] && [ "$out" != - ] && [ -e "$out" ] && [ -n "$(find "$out" -type f 2>/dev/null | head -1)" ]; then
    verdict="left output"
  fi
  [ "$code" -eq 0 ] && [ "$out" != - ] && rm -rf "$out"
  case $verdict in ok | accepted) pass ;; *) fail "$sub / $input: $verdict: $(head -3 "$work/stderr")"; bad=$((bad + 1)) ;; esac
  rows+=("| \`$sub\` | $input | $code | $message | $verdict, $((SECONDS - start)) s |")
}

o=$work/out
# project / unproject
row project "missing sensor file" - error -- project --sensor "$f/none.yaml" --points "$f/points.csv"
row project "empty sensor file" - error -- project --sensor "$f/empty.yaml" --points "$f/points.csv"
row project "a directory as the sensor file" - error -- project --sensor "$f" --points "$f/points.csv"
row project "a directory as the points file" "$o.csv" error -- project --sensor "$sensor" --points "$f" --out "$o.csv"
row project "corrupt YAML" - error -- project --sensor "$f/corrupt.yaml" --points "$f/points.csv"
row project "NaN focal length" - error -- project --sensor "$f/sensor-nan.yaml" --points "$f/points.csv"
row project "infinite sphere radius" - error -- project --sensor "$f/sensor-inf.yaml" --points "$f/points.csv"
row project "huge m (1e308)" - error -- project --sensor "$f/sensor-huge.yaml" --points "$f/points.csv"
row project "negative image size" - error -- project --sensor "$f/sensor-negative.yaml" --points "$f/points.csv"
row project "rim outside the mirror's domain" - error -- project --sensor "$f/sensor-domain.yaml" --points "$f/points.csv"
row project "tabulated profile folding back" - error -- project --sensor "$f/sensor-table.yaml" --points "$f/points.csv"
row project "point 1e400 (overflow)" "$o.csv" error -- project --sensor "$sensor" --points "$f/points-huge.csv" --out "$o.csv"
row project "row with 2 of 3 columns" "$o.csv" error -- project --sensor "$sensor" --points "$f/points-short.csv" --out "$o.csv"
row project "empty points file" "$o.csv" error -- project --sensor "$sensor" --points "$f/empty.csv" --out "$o.csv"
row unproject "NaN pixel" "$o.csv" error -- unproject --sensor "$sensor" --pixels "$f/pixels-nan.csv" --out "$o.csv"
row unproject "output directory cannot be created" - error -- unproject --sensor "$sensor" --pixels "$data/pixels/grid-25px.csv" --out "$readonly_dir/rays.csv"
# characterize / parallax
row characterize "NaN focal length" "$o" error -- characterize --sensor "$f/sensor-nan.yaml" --out "$o"
row characterize "output directory cannot be created" - error -- characterize --sensor "$sensor" --out "$readonly_dir"
row characterize "negative f-number" "$o" error -- characterize --sensor "$sensor" --f-number -4 --out "$o"
row parallax "negative distance" "$o" error -- parallax --sensor "$sensor" --distance-mm -100 --out "$o"
row parallax "NaN distance" "$o" error -- parallax --sensor "$sensor" --n nan --out "$o"
row parallax "distance 1e300 mm" "$o" error -- parallax --sensor "$sensor" --distance-mm 1e300 --out "$o"
row parallax "corrupt maps.json" "$o" error -- parallax --maps "$f/maps-corrupt" --n 7 --out "$o"
# target / render
row target "unknown target type" "$o.png" error -- target --spec "$f/target-type.yaml" --out "$o.png"
row target "negative tag size" "$o.png" error -- target --spec "$f/target-negative.yaml" --out "$o.png"
row target "empty spec" "$o.png" error -- target --spec "$f/empty.yaml" --out "$o.png"
row render "negative samples per pixel" "$o" error -- render --scene "$f/scene-negative.yaml" --out "$o"
row render "NaN view distance" "$o" error -- render --scene "$f/scene-nan.yaml" --out "$o"
row render "missing scene" "$o" error -- render --scene "$f/none.yaml" --out "$o"
row render "board warp with one value" "$o" error -- render --scene "$f/scene-warp.yaml" --out "$o"
row render "JPEG quality 120" "$o" error -- render --scene "$f/scene-jpeg.yaml" --out "$o"
row render "view prefix ../far" "$o" error -- render --scene "$f/scene-escape.yaml" --out "$o"
row diff "missing calibration" "$o" error -- diff "$f/none" "$sensor" --out "$o"
row diff "a sensor of another image size" "$o" error -- diff "$sensor" "$data/sensors/ohte-sph-misaligned-guess.yaml" --out "$o"
row diff "distance 1e300 mm" "$o" error -- diff "$sensor" "$sensor" --distance-mm 1e300 --out "$o"
# detect / calibrate
row detect "truncated PNG" "$o.json" error -- detect --target "$grid" --images "$f/truncated" --out "$o.json"
row detect "non-image file named .png" "$o.json" error -- detect --target "$grid" --images "$f/notimage" --out "$o.json"
row detect "16-bit PNG" "$o.json" accepted -- detect --target "$grid" --images "$f/deep" --out "$o.json"
row detect "colour PNG" "$o.json" accepted -- detect --target "$grid" --images "$f/colour" --out "$o.json"
row detect "a 64 x 2 px image" "$o.json" accepted -- detect --target "$grid" --images "$f/strip" --out "$o.json"
row calibrate "a 64 x 2 px image" "$o" error -- calibrate --target "$grid" --images "$f/strip" --out "$o"
row detect "wrong target spec (type)" "$o.json" error -- detect --target "$f/target-type.yaml" --images "$rendered" --out "$o.json"
row detect "empty image directory" "$o.json" error -- detect --target "$grid" --images "$f/no-images" --out "$o.json"
row detect "--checkerboard-edges without --sensor" "$o.json" error -- detect --target "$grid" --images "$rendered" --checkerboard-edges --out "$o.json"
row calibrate "--checkerboard-edges with an aprilgrid" "$o" error -- calibrate --target "$grid" --images "$f/strip" --sensor "$guess" --checkerboard-edges --out "$o"
row calibrate "--checkerboard-edges with --detections" "$o" error -- calibrate --target "$data/targets/checkerboard-8x6-30mm.yaml" --detections "$f/detections-one.json" --sensor "$guess" --checkerboard-edges --out "$o"
row calibrate "--checkerboard-edges with one detection pass" "$o" error -- calibrate --target "$data/targets/checkerboard-8x6-30mm.yaml" --images "$f/strip" --sensor "$guess" --checkerboard-edges --detection-passes 1 --out "$o"
row calibrate "--checkerboard-edges with --checkerboard-subpixel" "$o" error -- calibrate --target "$data/targets/checkerboard-8x6-30mm.yaml" --images "$f/strip" --sensor "$guess" --checkerboard-edges --checkerboard-subpixel --out "$o"
row calibrate "--checkerboard-subpixel with an aprilgrid" "$o" error -- calibrate --target "$grid" --images "$f/strip" --sensor "$guess" --checkerboard-subpixel --out "$o"
row calibrate "one truncated image" "$o" error -- calibrate --target "$grid" --images "$f/truncated" --sensor "$guess" --out "$o"
row calibrate "huge corner coordinate" "$o" error -- calibrate --target "$grid" --detections "$f/detections-huge.json" --sensor "$guess" --out "$o"
row calibrate "corners found on another board" "$o" error -- calibrate --target "$grid" --detections "$f/detections-other-board.json" --sensor "$guess" --out "$o"
row calibrate "corner pixel 1e300" "$o" error -- calibrate --target "$grid" --detections "$f/detections-far.json" --sensor "$guess" --out "$o"
row calibrate "corner id 2.5" "$o" error -- calibrate --target "$grid" --detections "$f/detections-id-fraction.json" --sensor "$guess" --out "$o"
row calibrate "corner id true" "$o" error -- calibrate --target "$grid" --detections "$f/detections-id-bool.json" --sensor "$guess" --out "$o"
row calibrate "a directory as the detections file" "$o" error -- calibrate --target "$grid" --detections "$f" --sensor "$guess" --out "$o"
row detect "a directory as the target spec" "$o.json" error -- detect --target "$f" --images "$rendered" --out "$o.json"
row "design ode" "a directory as the law table" "$o" error -- design ode --law table --law-table "$f" --focal-length-mm 12.5 --distance-mm 2000 --start-height-mm 155 --rim-limit-mm 30 --rho1-mm 2.4 --out "$o"
row calibrate "empty detections file" "$o" error -- calibrate --target "$grid" --detections "$f/empty.csv" --sensor "$guess" --out "$o"
row calibrate "negative tag size" "$o" error -- calibrate --target "$f/target-negative.yaml" --images "$rendered" --sensor "$guess" --out "$o"
# remap / unwarp / export-central
row remap "NaN distance" "$o" error -- remap --sensor "$sensor" --view panorama --size 64x16 --distance-mm nan --out "$o"
row remap "n = 1e300" "$o" error -- remap --sensor "$sensor" --view panorama --size 64x16 --n 1e300 --out "$o"
row remap "negative size" "$o" error -- remap --sensor "$sensor" --view panorama --size -64x16 --infinity --out "$o"
row remap "huge size (1e6 x 1e6)" "$o" error -- remap --sensor "$sensor" --view panorama --size 1000000x1000000 --infinity --out "$o"
row remap "output directory cannot be created" - error -- remap --sensor "$sensor" --view panorama --size 64x16 --infinity --out "$readonly_dir"
row unwarp "truncated PNG" "$o.png" error -- unwarp --maps "$f/maps" --input "$f/truncated.png" --out "$o.png"
row unwarp "non-image input" "$o.png" error -- unwarp --maps "$f/maps" --input "$f/points.csv" --out "$o.png"
row unwarp "corrupt maps.json" "$o.png" error -- unwarp --maps "$f/maps-corrupt" --input "$omni" --out "$o.png"
# Videos: OpenCV tried GStreamer and an image-sequence reader first, 7-11 lines before ours.
: >"$f/empty.avi"
head -c 3000 "$omni" >"$f/garbage.mp4"
row unwarp "missing video" "$o.avi" error -- unwarp --maps "$f/maps" --input "$f/none.avi" --out "$o.avi"
row unwarp "empty video" "$o.avi" error -- unwarp --maps "$f/maps" --input "$f/empty.avi" --out "$o.avi"
row unwarp "corrupt video" "$o.avi" error -- unwarp --maps "$f/maps" --input "$f/garbage.mp4" --out "$o.avi"
row unwarp "16-bit input" "$o.png" processed -- unwarp --maps "$f/maps-1040" --input "$f/deep/near000.png" --out "$o.png"
row export-central "NaN distance" "$o" error -- export-central --sensor "$sensor" --model mei --distance-mm nan --out "$o"
row export-central "distance 1e300 mm" "$o" error -- export-central --sensor "$sensor" --model mei --distance-mm 1e300 --out "$o"
row export-central "infinite sphere radius" "$o" error -- export-central --sensor "$f/sensor-inf.yaml" --model mei --out "$o"
# design
row "design ode" "empty spec" "$o" error -- design ode --spec "$f/empty.yaml" --out "$o"
row "design ode" "negative focal length" "$o" error -- design ode --law linear --focal-length-mm -12.5 --distance-mm 2000 --start-height-mm 155 --rim-limit-mm 30 --rho1-mm 2.4 --gain 2000 --offset-mm -4000 --out "$o"
row "design fit" "NaN rim angle" "$o" error -- design fit --profile sphere --rim-omega nan --out "$o"
row "design fit" "output directory cannot be created" - error -- design fit --profile sphere --out "$readonly_dir"
# Disk full: an 8 KiB file-size limit (SIGXFSZ ignored, so writes fail with EFBIG).
runner=(bash -c 'ulimit -f 8; trap "" XFSZ; exec "$0" "$@"' "$omnical")
row remap "disk full while writing the maps" "$o" write-error -- remap --sensor "$sensor" --view panorama --size 720x180 --infinity --out "$o"
row render "disk full while writing images" "$o" write-error -- render --scene "$f/scene-small.yaml" --out "$o"
row "design ode" "disk full while writing the profile" "$o" write-error -- design ode --spec "$data/designs/gaechter-uniform.yaml" --out "$o"
runner=("$omnical")

{
  echo "# Bad input against every subcommand"
  echo
  echo "Generated by \`tests/cli/bad_input_table.sh\` (ctest \`cli.bad_input_table\`); do not edit. Each row:"
  echo "the input, the exit code, the error line on stderr, and the verdict: ok = exit 2 with one"
  echo "error line (warnings such as skipped images may come before it) and nothing left at the"
  echo "output path (for a disk that fills up: no temporary file left; the files completed"
  echo "before the failing write stay, each whole); accepted = processed on purpose (images are"
  echo "converted to 8-bit grey). Paths are shown relative to the repository or the test's"
  echo "temporary directory."
  echo
  echo "| subcommand | input | exit | message | verdict |"
  echo "| --- | --- | --- | --- | --- |"
  printf '%s\n' "${rows[@]}"
} >"$table.tmp" && mv "$table.tmp" "$table"
echo "$table: ${#rows[@]} rows, $bad bad"
summary bad_input_table
