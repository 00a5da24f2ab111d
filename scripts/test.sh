#!/usr/bin/env bash
# Installs what is missing, builds omnical in Release with its tests, and runs them all
# with CTest; then builds a second tree under AddressSanitizer + UndefinedBehaviorSanitizer
# (build/test-sanitize, OMNICAL_SANITIZE=ON, -O1) and runs the suite again there, less what
# would take it past CI's time (measured under the sanitizers on 2 cores): the labels
# `bench` (speed ratios mean nothing there) and `slow` (the two render -> calibrate
# end-to-end scripts), cli.project_unproject_and_bad_input (793 s: its calibrations; the
# bad input of every subcommand runs there as cli.bad_input_table), the Monte Carlo
# tests BundleFit.StandardDeviationsHold* (177 + 68 s) and
# FitCovariance.AgreesWithAMonteCarloOverNoisyObservations (100 fits, 37 s in Release), Renderer.CornersSitWhereTheGroundTruthSays
# (122 s) and cli.interrupt_leaves_previous_outputs (157 s), and the fits of
# calibration_trust_test (5-150 s each in Release: its Monte Carlo runs 30 fits; the cheap
# ones, rim and tolerance checks, stay) and BoardScale.RefusesADistantGiant (296 s there;
# RealImages runs the board-size check under the sanitizers). One test program is not
# built there at all (tests/CMakeLists.txt): jet_derivatives_test, Jets against central
# differences, 56 s to compile there; bundle_fit_harness_test's GradientChecker checks
# the same Jets model by model. The Python module and its
# pytest suite run in the Release pass only: an ASan-built extension cannot load into
# Debian's uninstrumented interpreter (ASan must be the first library loaded), so the
# sanitizer tree is configured with OMNICAL_PYTHON=OFF; the C++ code the module calls is
# the same code the sanitizer pass runs. OMNICAL_SANITIZE_PASS=0 skips the second pass.
# Usage: scripts/test.sh [extra ctest arguments, for both passes]
set -euo pipefail
omnical_build_kind=test
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
install_dependencies
configure_and_build -DOMNICAL_BUILD_TESTS=ON -DOMNICAL_BUILD_BENCHMARKS=ON -DOMNICAL_WERROR=ON
(cd "$build_dir" && ctest --output-on-failure -j "$jobs" "$@")

[ "${OMNICAL_SANITIZE_PASS:-1}" = 0 ] && exit 0
echo "omnical: second pass under AddressSanitizer + UndefinedBehaviorSanitizer"
build_dir=${OMNICAL_SANITIZE_BUILD_DIR:-$omnical_root/build/test-sanitize}
configure_and_build -DCMAKE_BUILD_TYPE=Sanitize -DCMAKE_CXX_FLAGS_SANITIZE=-O1 -DOMNICAL_BUILD_TESTS=ON \
  -DOMNICAL_BUILD_BENCHMARKS=OFF -DOMNICAL_WERROR=ON -DOMNICAL_SANITIZE=ON -DOMNICAL_PYTHON=OFF
# Any report fails the test that triggered it: UBSan does not recover (compile flag), ASan
# aborts, leaks count.
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
too_slow='cli.project_unproject_and_bad_input|StandardDeviationsHold|AgreesWithAMonteCarlo|CornersSitWhereTheGroundTruthSays'
too_slow+='|cli.interrupt_leaves|RecoversABoardWarp|CalibrateGeneralisation.Noisy|KnotChoice|FindsCheckerboardsTheOmniSearchMisses'
too_slow+='|MonteCarloSpread|WrongBasin|LeavesOutAView|ToleranceEnters|NearOnlyDistortion|KeepsEveryCornerOfANearly|BoardScale'
# The installed examples calibrate a set twice: the Release pass covers them.
too_slow+='|install.find_package_consumers'
# Numerical sweeps whose code the pass runs in shorter tests (measured under the sanitizers
# on a clean clone: 180, 4 x 60, 160 and 121 s of its 837 s): the interpolated remap grid
# against per-pixel tables over every sensor, screen and surface (the same grid code:
# VirtualView.TableStays..., 30 s), the rendered unwarp boards (cli.remap_unwarp_exports
# remaps and unwarps), the exact-observation fit of the aligned hyperboloid (the other 23
# models' run) and the calibration record round trip (RecordWithAViewLeftOutRoundTrips).
too_slow+='|RemapTable.InterpolatedGridStaysWithinAHundredthOfAPixel|UnwarpedPanorama'
too_slow+='|RecoversTheTruthFromExactObservations/hyperboloid_pinhole_aligned|RecordRoundTripsThroughCalibrationJson'
(cd "$build_dir" && ctest --output-on-failure -j "$jobs" -LE 'bench|slow' -E "$too_slow" "$@")
