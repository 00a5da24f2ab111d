#!/usr/bin/env bash
# cmake --install into a temporary prefix, then build and run a downstream project that
# uses find_package(omnical). Usage: install_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build_dir=$1
source_dir=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# Logs are shown only when a step fails.
run() { "$@" >"$work/log" 2>&1 || { cat "$work/log"; echo "FAILED: $*"; exit 1; }; }
run cmake --install "$build_dir" --prefix "$work/prefix"
test -x "$work/prefix/bin/omnical"
test -f "$work/prefix/include/omnical/model/catadioptric.h"
run cmake -S "$source_dir/tests/install/consumer" -B "$work/consumer" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$work/prefix"
run cmake --build "$work/consumer"
"$work/consumer/consumer" "$source_dir/datasets-synthetic/sensors/ohte-sph.yaml"
"$work/prefix/bin/omnical" --help >/dev/null
echo "1 passed, 0 failed"
