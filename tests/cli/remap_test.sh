#!/usr/bin/env bash
# omnical remap / unwarp from the command line: the three export formats against each
# other (ffmpeg's remap filter vs cv::remap INTER_NEAREST on the rounded maps, pixel for
# pixel; NumPy's np.load vs the OpenCV float maps), image and video unwarping, and the
# bad-input policy. Usage: remap_test.sh OMNICAL_BINARY SOURCE_DIR MAPCHECK_BINARY
set -u
omnical=$1
source_dir=$(cd "$2" && pwd)
mapcheck=$3
sensors=$source_dir/datasets-synthetic/sensors
omni=$source_dir/datasets-synthetic/rendered/ohte-sph-misaligned-near/near-front.png  # 1040 x 1040
omni_aligned=$source_dir/datasets-synthetic/rendered/ohte-sph-near/near-front.png  # 1000 x 1000
source "$(dirname "${BASH_SOURCE[0]}")/harness.sh"


# --- all three formats from one run ------------------------------------------------------
maps=$work/maps
"$omnical" remap --sensor "$sensors/ohte-sph-misaligned.yaml" --view panorama --size 720x160 --n 7 \
  --format opencv,ffmpeg,npy --out "$maps" --quiet || fail "remap exited $?"
for f in maps.json maps.yml.gz maps_fixed.yml.gz xmap.pgm ymap.pgm map_x.npy map_y.npy remap_error.png; do
  check test -s "$maps/$f"
done
check grep -q '"type": "panorama"' "$maps/maps.json"
check grep -q '"column_direction"' "$maps/maps.json"
check grep -q '"error_at_other_distances"' "$maps/maps.json"
# The exactness check the file reports (table vs fresh exact projections): a misaligned
# sensor's table is interpolated on a grid, within its 0.01 px bound; with --per-pixel it
# is float-exact.
exactness() { python3 -c "import json,sys; j=json.load(open(sys.argv[1])); print(j['method'].replace(' ', '_'), j['exactness_check']['max_error_px'])" "$1/maps.json"; }
read -r method exact < <(exactness "$maps")
check test "$method" = interpolated_grid
check awk -v e="$exact" 'BEGIN { exit !(e < 0.01) }'
"$omnical" remap --sensor "$sensors/ohte-sph-misaligned.yaml" --view panorama --size 720x160 --n 7 --per-pixel \
  --format npy --out "$work/per-pixel" --quiet || fail "remap --per-pixel exited $?"
read -r method exact < <(exactness "$work/per-pixel")
check test "$method" = per_pixel
check awk -v e="$exact" 'BEGIN { exit !(e < 0.001) }'

# ffmpeg's remap filter (integer maps) vs cv::remap INTER_NEAREST on the rounded maps.
if command -v ffmpeg >/dev/null; then
  ffmpeg -loglevel error -y -i "$omni" -i "$maps/xmap.pgm" -i "$maps/ymap.pgm" \
    -filter_complex "[0:v]format=gray[g];[g][1:v][2:v]remap=fill=black,format=gray" -frames:v 1 "$work/ffmpeg.png" ||
    fail "ffmpeg remap failed"
  "$mapcheck" ffmpeg "$omni" "$maps/maps.yml.gz" "$work/ffmpeg.png" && pass || fail "ffmpeg output differs from cv::remap"
else
  fail "ffmpeg not installed (scripts/test.sh installs it)"
fi

# NumPy loads the .npy maps; they equal the OpenCV float maps (dumped as raw float32).
"$mapcheck" dump "$maps/maps.yml.gz" "$work/x.f32" "$work/y.f32" || fail "dump failed"
if /usr/bin/python3 -c "import numpy" 2>/dev/null; then
  /usr/bin/python3 - "$maps" "$work" <<'PY' && pass || fail "npy maps differ from the OpenCV maps"
import sys, numpy as np
maps, work = sys.argv[1], sys.argv[2]
x, y = np.load(maps + "/map_x.npy"), np.load(maps + "/map_y.npy")
assert x.dtype == np.float32 and x.shape == (160, 720), (x.dtype, x.shape)
ox = np.fromfile(work + "/x.f32", dtype="<f4").reshape(160, 720)
oy = np.fromfile(work + "/y.f32", dtype="<f4").reshape(160, 720)
assert np.array_equal(x, ox) and np.array_equal(y, oy)
assert (x >= 0).mean() > 0.5  # most of the panorama sees the mirror
PY
else
  fail "python3-numpy not installed (scripts/test.sh installs it)"
fi

# --- unwarp: image from the maps, image from view options, video ---------------------------
"$omnical" unwarp --maps "$maps" --input "$omni" --out "$work/pano.png" --quiet || fail "unwarp --maps exited $?"
check test -s "$work/pano.png"
"$mapcheck" same-size "$work/pano.png" 720 160 && pass || fail "unwarped image size"
"$omnical" unwarp --sensor "$sensors/ohte-sph.yaml" --view perspective --pan-deg 0 --tilt-deg -20 --hfov-deg 50 \
  --infinity --size 200x150 --input "$omni_aligned" --out "$work/persp.png" --quiet || fail "unwarp with view options exited $?"
"$mapcheck" same-size "$work/persp.png" 200 150 && pass || fail "perspective size"
if command -v ffmpeg >/dev/null; then
  ffmpeg -loglevel error -y -loop 1 -i "$omni" -t 0.4 -r 10 -c:v mjpeg -q:v 3 "$work/omni.avi" || fail "making a test video"
  "$omnical" unwarp --maps "$maps" --input "$work/omni.avi" --out "$work/pano.avi" --quiet || fail "video unwarp exited $?"
  frames=$(ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames -of csv=p=0 "$work/pano.avi")
  check test "$frames" -eq 4
  size=$(ffprobe -v error -select_streams v:0 -show_entries stream=width,height -of csv=p=0 "$work/pano.avi")
  check test "$size" = "720,160"
fi

# --- parallax --maps ---------------------------------------------------------------------
"$omnical" parallax --maps "$maps" --out "$work/parallax-maps" --quiet || fail "parallax --maps exited $?"
check test -s "$work/parallax-maps/maps-error.png"
check test -s "$work/parallax-maps/maps-error.csv"
# At the table's own distance (n = 7) the error vanishes.
own=$(awk -F, '$1 == 7 { print $3 }' "$work/parallax-maps/maps-error.csv")
check awk -v e="$own" 'BEGIN { exit !(e != "" && e < 1e-6) }'

# --- bad input ---------------------------------------------------------------------------
expect_error "view outside the field" "outside the mirror's field" "$work/bad" -- \
  remap --sensor "$sensors/ohte-sph.yaml" --view perspective --tilt-deg 89 --hfov-deg 20 --n 7 --out "$work/bad"
expect_error "distance <= 0" "distance" "$work/bad" -- \
  remap --sensor "$sensors/ohte-sph.yaml" --view panorama --distance-mm -5 --out "$work/bad"
expect_error "no distance" "--distance-mm" "$work/bad" -- \
  unwarp --sensor "$sensors/ohte-sph.yaml" --view panorama --input "$omni_aligned" --out "$work/bad/x.png"
expect_error "bad size" "--size" "$work/bad" -- \
  remap --sensor "$sensors/ohte-sph.yaml" --view panorama --size 100by20 --infinity --out "$work/bad"
expect_error "missing sensor" "nope.yaml" "$work/bad" -- \
  remap --sensor "$work/nope.yaml" --view panorama --infinity --out "$work/bad"
# Inconsistent map files: maps.json from one run, maps.yml.gz from another size.
mkdir -p "$work/mixed"
cp "$maps/maps.json" "$work/mixed/"
"$omnical" remap --sensor "$sensors/ohte-sph-misaligned.yaml" --view panorama --size 360x80 --n 7 --out "$work/other" --quiet
cp "$work/other/maps.yml.gz" "$work/mixed/"
expect_error "inconsistent maps" "inconsistent map files" "$work/bad" -- \
  unwarp --maps "$work/mixed" --input "$omni" --out "$work/bad/x.png"
expect_error "maps and view options" "either --maps" "$work/bad" -- \
  unwarp --maps "$maps" --view panorama --infinity --input "$omni" --out "$work/bad/x.png"
expect_error "wrong image size" "sensor's image" "$work/bad" -- \
  unwarp --maps "$maps" --input "$work/pano.png" --out "$work/bad/x.png"
printf 'not an image' >"$work/corrupt.png"
expect_error "corrupt image" "corrupt.png" "$work/bad" -- \
  unwarp --maps "$maps" --input "$work/corrupt.png" --out "$work/bad/x.png"

summary remap_test
