#!/usr/bin/env bash
# Installs what is missing, builds omnical in Release with its tests, and runs them all
# with CTest; then a second pass under AddressSanitizer + UndefinedBehaviorSanitizer (-O1,
# build/test-sanitize), chosen by OMNICAL_SANITIZE_PASS:
#   core (default, CI) — the layers below calib (model, formats, design, correction;
#     OMNICAL_CORE_ONLY=ON) and every test of theirs but two numerical sweeps (below):
#     projection, the batch kernels' baseline build, the sensor, profile and design-spec
#     parsers with their bad-input tables, mirror design, optics, remap tables, unwarp and
#     parallax jobs. ~5 min on 2 cores, where the whole suite under the sanitizers took ~18
#     (build 643 s, tests 457 s on an idle machine) and kept CI over the issue's 15 min.
#     Calibration (detection, the bundle fit), the renderer, the report and the CLI run
#     sanitized only in the full pass; the parsers of their files (detections, targets,
#     scenes, maps) run under clang's ASan + UBSan in the fuzz harness (scripts/fuzz.sh).
#   full — every layer and the CLI, the suite less what took it past CI's time there
#     (measured under the sanitizers on 2 cores): the labels `bench` and `slow`, the
#     Monte Carlo fits, the long CLI scripts and sweeps named in $too_slow below.
#   0 — no second pass.
# The Python module and its pytest suite run in the Release pass only: an ASan-built
# extension cannot load into Debian's uninstrumented interpreter (ASan must be the first
# library loaded), so the sanitizer tree has OMNICAL_PYTHON=OFF. jet_derivatives_test
# (56 s to compile there) is not built in it (tests/CMakeLists.txt).
# The sanitizer tree is configured and built while the Release tests run, at the lowest
# CPU priority (nice 19): it takes the CPU the tests leave idle (subprocesses starting,
# files, single-threaded steps) and yields the rest, so the speed-ratio tests still get
# their core.
# Usage: scripts/test.sh [extra ctest arguments, for both passes]
set -euo pipefail
omnical_build_kind=test
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
sanitize_pass=${OMNICAL_SANITIZE_PASS:-core}
case $sanitize_pass in
  0) ;;
  core) scope=(-DOMNICAL_CORE_ONLY=ON) ;;
  full) scope=(-DOMNICAL_CORE_ONLY=OFF) ;;
  *) echo "omnical: OMNICAL_SANITIZE_PASS must be core, full or 0, got '$sanitize_pass'" >&2; exit 2 ;;
esac
# Each phase's start in seconds since this script began: the CI log then says where its
# time went (the CI budget is ~15 min on 2 cores).
phase() { echo "omnical: [${SECONDS} s] $*"; }
phase "dependencies"
install_dependencies
phase "Release build ($build_dir)"
configure_and_build -DOMNICAL_BUILD_TESTS=ON -DOMNICAL_BUILD_BENCHMARKS=ON -DOMNICAL_WERROR=ON
release_dir=$build_dir
sanitize_dir=${OMNICAL_SANITIZE_BUILD_DIR:-$omnical_root/build/test-sanitize}

if [ "$sanitize_pass" != 0 ]; then
  sanitize_log=$release_dir/sanitize-build.log
  echo "omnical: building the sanitizer tree ($sanitize_pass) beside the tests, at nice 19 (log: $sanitize_log)"
  set -m  # its own process group, so a failure here stops the whole build (trap below)
  (
    renice -n 19 "$BASHPID" >/dev/null
    build_dir=$sanitize_dir
    configure_and_build -DCMAKE_BUILD_TYPE=Sanitize -DCMAKE_CXX_FLAGS_SANITIZE=-O1 -DOMNICAL_BUILD_TESTS=ON \
      -DOMNICAL_BUILD_BENCHMARKS=OFF -DOMNICAL_WERROR=ON -DOMNICAL_SANITIZE=ON -DOMNICAL_PYTHON=OFF "${scope[@]}"
  ) >"$sanitize_log" 2>&1 &
  sanitize_build=$!
  set +m
  trap 'kill -- -"$sanitize_build" 2>/dev/null || true' EXIT
fi
# The speed ratios (label bench) run alone, after the sanitizer build: measured with a
# compiler on the other core, bench.projection_speed_ratio's axial sphere cost 20.3x its
# baseline in one clean-clone CI run (bound 20x) against 11.2x on an idle machine.
phase "Release tests (all but the label bench)"
(cd "$release_dir" && ctest --output-on-failure -j "$jobs" -LE bench "$@")
if [ "$sanitize_pass" = 0 ]; then
  phase "speed ratios (label bench)"
  (cd "$release_dir" && ctest --output-on-failure -L bench "$@")
  phase "done"
  exit 0
fi
phase "waiting for the sanitizer build"

if ! wait "$sanitize_build"; then
  tail -40 "$sanitize_log" >&2
  echo "omnical: the sanitizer build failed (log: $sanitize_log)" >&2
  exit 1
fi
trap - EXIT
phase "speed ratios (label bench)"
(cd "$release_dir" && ctest --output-on-failure -L bench "$@")
phase "second pass under AddressSanitizer + UndefinedBehaviorSanitizer ($sanitize_pass)"
# Any report fails the test that triggered it: UBSan does not recover (compile flag), ASan
# aborts, leaks count.
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# A numerical sweep whose code shorter tests run (180 s under the sanitizers on a clean
# clone): the interpolated remap grid against per-pixel tables over every sensor, screen
# and surface (the same grid code: VirtualView.TableStays..., 30 s).
too_slow='RemapTable.InterpolatedGridStaysWithinAHundredthOfAPixel'
if [ "$sanitize_pass" = full ]; then
  too_slow+='|cli.project_unproject_and_bad_input|StandardDeviationsHold|AgreesWithAMonteCarlo|CornersSitWhereTheGroundTruthSays'
  too_slow+='|cli.interrupt_leaves|RecoversABoardWarp|CalibrateGeneralisation.Noisy|KnotChoice.Chooses|FindsCheckerboardsTheOmniSearchMisses'
  too_slow+='|MonteCarloSpread|WrongBasin|LeavesOutAView|ToleranceEnters|NearOnlyDistortion|KeepsEveryCornerOfANearly|BoardScale'
  too_slow+='|install.find_package_consumers|UnwarpedPanorama'
  too_slow+='|RecoversTheTruthFromExactObservations/hyperboloid_pinhole_aligned|RecordRoundTripsThroughCalibrationJson'
  too_slow+='|WithoutAGuessTheLensIsChosen'
fi
(cd "$sanitize_dir" && ctest --output-on-failure -j "$jobs" -LE 'bench|slow' -E "$too_slow" "$@")
phase "done"
