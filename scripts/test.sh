#!/usr/bin/env bash
# Installs what is missing, builds omnical in Release with its tests, and runs them all
# with CTest. Usage: scripts/test.sh [extra ctest arguments]
set -euo pipefail
omnical_build_kind=test
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
install_dependencies
configure_and_build -DOMNICAL_BUILD_TESTS=ON -DOMNICAL_BUILD_BENCHMARKS=ON -DOMNICAL_WERROR=ON
cd "$build_dir"
ctest --output-on-failure -j "$jobs" "$@"
