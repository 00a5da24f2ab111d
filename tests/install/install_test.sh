#!/usr/bin/env bash
# cmake --install into a temporary prefix, then build the three example consumers
# (tests/install/{project,calibrate,remap}, linked from docs/library-api.md) against it:
#  1. project: links only omnical::model; its link line must name no OpenCV, AprilTag or
#     yaml-cpp;
#  2. calibrate: calibrates four views of a bundled rendered set from C++ and must reproduce the
#     installed CLI's calibration.json to 1e-9;
#  3. remap: builds a parallax-corrected panorama table, checks it against direct
#     projections (< 0.01 px) and applies it to a rendered image;
#  4. with PYTHON given: the installed Python package imports from the prefix's site
#     directory (not the build tree) and projects a point as the installed CLI does.
# Also: only public headers are installed, and all of them compile in one unit.
# Usage: install_test.sh BUILD_DIR SOURCE_DIR [PYTHON]
set -euo pipefail
build_dir=$1
source_dir=$2
python=${3:-}
data=$source_dir/datasets-synthetic
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# Logs are shown only when a step fails.
run() { "$@" >"$work/log" 2>&1 || { cat "$work/log"; echo "FAILED: $*"; exit 1; }; }
fail() { echo "FAILED: $*"; exit 1; }
passed=0
prefix=$work/prefix
run cmake --install "$build_dir" --prefix "$prefix"
test -x "$prefix/bin/omnical" || fail "no installed omnical binary"
# The image codecs plugin, loaded on first use (model/io/codecs/image_codecs.h).
plugin=$(find "$prefix" -path "*/omnical/libomnical_codecs_plugin.so" | head -1)
[ -n "$plugin" ] || fail "no installed codecs plugin (<libdir>/omnical/libomnical_codecs_plugin.so)"
# ... and the installed CLI loads that one (beside it), not the build tree's, when it first
# writes an image.
LD_DEBUG=files "$prefix/bin/omnical" -q target --spec "$data/targets/aprilgrid-6x6-30mm.yaml" --dpi 20 \
  --out "$work/target.png" 2>"$work/loader.log" || { tail -5 "$work/loader.log"; fail "installed omnical target"; }
# The plugin's own libraries are "needed by" the file the loader took, whichever way it was
# named (a path, or a bare name searched through RUNPATH).
loaded_plugin() {  # loaded_plugin WHO: $work/loader.log (LD_DEBUG=files) shows the installed plugin
  grep -q "needed by $plugin " "$work/loader.log" ||
    fail "$1: did not load $plugin: $(grep -o 'needed by [^ ]*codecs_plugin[^ ]*' "$work/loader.log" | head -1)"
}
loaded_plugin "the installed CLI"
passed=$((passed + 1))
# The codecs component asked for alone configures, links and reads an image.
mkdir "$work/codecs_only"
cat >"$work/codecs_only/CMakeLists.txt" <<'CMAKE'
cmake_minimum_required(VERSION 3.22)
project(codecs_only LANGUAGES CXX)
set(CMAKE_CXX_STANDARD 17)
find_package(omnical 0.1 REQUIRED COMPONENTS codecs)
add_executable(codecs_only main.cc)
target_link_libraries(codecs_only PRIVATE omnical::codecs)
CMAKE
cat >"$work/codecs_only/main.cc" <<'CC'
#include "model/io/codecs/image_codecs.h"
int main(int, char** argv) { return omnical::LoadImageFile(argv[1], 0).cols == 1000 ? 0 : 1; }
CC
run cmake -S "$work/codecs_only" -B "$work/codecs_only/build" -G Ninja -DCMAKE_PREFIX_PATH="$prefix"
run cmake --build "$work/codecs_only/build"
# ... through the installed plugin, which the package's RUNPATH finds for a program built
# anywhere against a prefix installed anywhere (not the build tree's, not by walking up).
LD_DEBUG=files "$work/codecs_only/build/codecs_only" "$data/rendered/ohte-sph-near/near000.png" \
  2>"$work/loader.log" || fail "codecs only: the image did not read as 1000 px wide"
loaded_plugin "codecs only"
passed=$((passed + 1))

# Public headers only: the internal ones stay in the source tree.
for internal in calib/bilinear.h calib/refine_corners.h calib/virtual_view.h correction/parallel_rows.h \
                model/io/yaml_field_reader.h model/io/codecs/codecs_plugin_table.h tools/cli_common.h; do
  [ ! -e "$prefix/include/omnical/$internal" ] || fail "internal header installed: $internal"
done
# ... and every installed header compiles on its own terms (one unit including them all).
find "$prefix/include/omnical" -name '*.h' | sort | sed "s#^$prefix/include/omnical/#\#include \"#; s#\$#\"#" >"$work/all.cc"
echo 'int main() { return 0; }' >>"$work/all.cc"
[ "$(grep -c include "$work/all.cc")" -gt 60 ] || fail "too few installed headers"
cat >"$work/CMakeLists.txt" <<'CMAKE'
cmake_minimum_required(VERSION 3.22)
project(all_headers LANGUAGES CXX)
set(CMAKE_CXX_STANDARD 17)
find_package(omnical 0.1 REQUIRED)
add_executable(all_headers all.cc)
target_link_libraries(all_headers PRIVATE omnical::report omnical::synthetic)
CMAKE
run cmake -S "$work" -B "$work/all" -G Ninja -DCMAKE_PREFIX_PATH="$prefix"
run cmake --build "$work/all"
passed=$((passed + 1))

build() {  # build EXAMPLE: configure and build tests/install/EXAMPLE against the prefix
  run cmake -S "$source_dir/tests/install/$1" -B "$work/$1" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$prefix"
  run cmake --build "$work/$1" -- -v
  cp "$work/log" "$work/$1.build.log"
}

# 1. Projection only.
build project
link_line=$(grep -- "-o project_point" "$work/project.build.log" || true)
[ -n "$link_line" ] || fail "project: no link line in the build log"
if grep -Eq "opencv|apriltag|yaml-cpp|nlohmann" <<<"$link_line"; then
  echo "$link_line"
  fail "project: the projection-only consumer links OpenCV, AprilTag or a file parser"
fi
"$work/project/project_point" || fail "project: the example failed"
passed=$((passed + 1))

# 2. Calibration from C++ equals the CLI's.
build calibrate
# Four of the bundled set's views: enough for a fit (3 needed), half the time of eight.
set_dir=$work/views
mkdir "$set_dir"
for view in near000 near001 near002 near003; do cp "$data/rendered/ohte-sph-near/$view.png" "$set_dir/"; done
run "$prefix/bin/omnical" -q calibrate --target "$data/targets/aprilgrid-6x6-30mm.yaml" --images "$set_dir" \
  --sensor "$data/sensors/ohte-sph.yaml" --threads 2 --out "$work/cli-calibration"
"$work/calibrate/calibrate_set" "$data/targets/aprilgrid-6x6-30mm.yaml" "$set_dir" "$data/sensors/ohte-sph.yaml" \
  "$work/cli-calibration/calibration.json" || fail "calibrate: the C++ calibration differs from the CLI's"
passed=$((passed + 1))

# 3. A parallax-corrected remap table, applied.
build remap
"$work/remap/remap_image" "$data/sensors/ohte-sph.yaml" "$set_dir/near000.png" "$work/panorama.png" ||
  fail "remap: the example failed"
test -s "$work/panorama.png" || fail "remap: no panorama written"
passed=$((passed + 1))

# 4. The Python package, installed under the prefix.
if [ -n "$python" ]; then
  module=$(find "$prefix" -name '_omnical*.so' | head -1)
  [ -n "$module" ] || fail "python: no installed extension module under $prefix"
  site=$(dirname "$(dirname "$module")")
  for file in __init__.py _omnical.pyi py.typed; do test -f "$site/omnical/$file" || fail "python: $file not installed"; done
  printf '400,-150,60\n' >"$work/point.csv"
  expected=$("$prefix/bin/omnical" project --sensor "$data/sensors/ohte-sph.yaml" --points "$work/point.csv" | tail -1)
  (cd "$work" && PYTHONPATH="$site" "$python" - "$data/sensors/ohte-sph.yaml" "$expected" "$site" \
     "$data/targets/aprilgrid-6x6-30mm.yaml" "$data/rendered/ohte-sph-near/near000.png" "$plugin") <<'PY' \
     || fail "python: the installed package"
import os
import sys
import omnical
sensor_path, expected, site, target, image, plugin = sys.argv[1:]
assert omnical.__file__.startswith(site), omnical.__file__
pixels, status = omnical.Sensor.load(sensor_path).project([[400.0, -150.0, 60.0]])
u, v, name = expected.split(",")
assert omnical.status_name(status[0]) == name, (status, expected)
assert abs(pixels[0, 0] - float(u)) < 1e-9 and abs(pixels[0, 1] - float(v)) < 1e-9, (pixels, expected)
# Reading an image loads the installed codecs plugin, not the build tree's.
assert omnical.detect(target, [image], threads=1).images[0].ids.size > 0
mapped = {line.split()[-1] for line in open("/proc/self/maps") if "libomnical_codecs_plugin" in line}
assert mapped == {os.path.realpath(plugin)}, (mapped, plugin)
PY
  passed=$((passed + 1))
fi
echo "$passed passed, 0 failed"
