#!/usr/bin/env bash
# Ctrl-C safety (issue 8): SIGINT in the middle of a long command leaves the previous
# outputs byte for byte and no temporary file. Two cases: a video unwarp (its output is
# written for the whole run, so the interrupt always lands mid-write: the handler must
# delete the temporary file) and a render into a directory holding an earlier render.
# Usage: interrupt_test.sh OMNICAL_BINARY SOURCE_DIR
set -u
omnical=$1
source_dir=$(cd "$2" && pwd)
data=$source_dir/datasets-synthetic
source "$(dirname "${BASH_SOURCE[0]}")/harness.sh"

# interrupt_when GLOB SECONDS -- ARGS: runs omnical ARGS, sends SIGINT SECONDS after a file
# matching GLOB exists (GLOB "-": after SECONDS; give up waiting at 20 s), and sets
# $status to its exit status.
interrupt_when() {
  local glob=$1 delay=$2
  shift 3
  "$omnical" "$@" >/dev/null 2>"$work/interrupt.err" &
  local pid=$! waited=0
  while [ "$glob" != - ] && [ $waited -lt 200 ] && ! compgen -G "$glob" >/dev/null; do sleep 0.1; waited=$((waited + 1)); done
  sleep "$delay"
  kill -INT "$pid"
  wait "$pid"
  status=$?
}
no_temporaries() { [ -z "$(find "$1" -name '*.tmp*' -o -name '.tmp*' | head -1)" ]; }

# Video: a 60-frame clip of a rendered omni image, unwarped to a panorama.
omni=$data/rendered/ohte-sph-near/near000.png
"$omnical" -q remap --sensor "$data/sensors/ohte-sph.yaml" --view panorama --size 720x180 --infinity --format opencv \
  --out "$work/maps" || fail "remap"
ffmpeg -loglevel error -y -loop 1 -i "$omni" -t 6 -r 10 -c:v mjpeg -q:v 3 "$work/long.avi" || fail "making a test video"
ffmpeg -loglevel error -y -loop 1 -i "$omni" -t 0.3 -r 10 -c:v mjpeg -q:v 3 "$work/short.avi" || fail "making a test video"
mkdir -p "$work/out"
"$omnical" -q unwarp --maps "$work/maps" --input "$work/short.avi" --out "$work/out/pano.avi" || fail "first unwarp"
before=$(md5sum <"$work/out/pano.avi")
interrupt_when "$work/out/.tmp*pano.avi" 0.3 -- unwarp --maps "$work/maps" --input "$work/long.avi" --out "$work/out/pano.avi"
check [ "$status" -eq 130 ]  # 128 + SIGINT: the process ended by the signal, not by finishing
check [ "$(md5sum <"$work/out/pano.avi")" = "$before" ]
check no_temporaries "$work/out"

# Render: an earlier render's files stay as they were. The second run renders other views
# (another seed, 30 of them), interrupted after its first views are done (render writes the set only
# when all are: never new images beside old ground truth), so any replaced file would show.
"$omnical" -q render --scene "$data/scenes/ohte-sph-far.yaml" --out "$work/render" || fail "first render"
(cd "$work/render" && md5sum ./* >"$work/render.md5")
sed -e "s#\.\./#$data/#" -e 's/seed: 21/seed: 22/' -e 's/count: 6/count: 30/' "$data/scenes/ohte-sph-far.yaml" >"$work/other.yaml"
interrupt_when - 4 -- render --scene "$work/other.yaml" --out "$work/render"
check [ "$status" -eq 130 ]
(cd "$work/render" && md5sum --quiet -c "$work/render.md5") && pass || fail "render outputs changed by the interrupted run"
check no_temporaries "$work/render"
summary interrupt_test
