#!/usr/bin/env bash
# A regression guard on the projection speed targets (>= 10 M axial and >= 5 M tilted
# projections per second per core): the batch projection's cost relative to a distorted
# pinhole projection measured in the same run must stay below generous bounds (measured
# about 48x and 80x; a regression that re-ran the solver per point gave 119x and 241x).
# Ratios survive a slow or busy machine; absolute rates would not.
# Usage: speed_check.sh PROJECTION_BENCHMARK_BINARY
set -euo pipefail
out=$(mktemp)
trap 'rm -f "$out"' EXIT
"$1" --benchmark_filter='Baseline|Project_' --benchmark_min_time=0.2 --benchmark_out="$out" --benchmark_out_format=json >/dev/null
python3 - "$out" <<'PY'
import json, sys
rates = {b["name"]: b["items_per_second"] for b in json.load(open(sys.argv[1]))["benchmarks"]}
baseline = rates["BM_Baseline_PinholeDistortedProjection"]
ok = True
for name, bound in (("BM_Project_AxialSphere", 100.0), ("BM_Project_TiltedPolynomial", 180.0)):
    ratio = baseline / rates[name]
    print(f"{name}: {rates[name] / 1e6:.2f} M/s, cost {ratio:.1f}x the pinhole baseline (bound {bound:.0f}x)")
    ok &= ratio < bound
print("1 passed, 0 failed" if ok else "0 passed, 1 failed")
sys.exit(0 if ok else 1)
PY
