#!/usr/bin/env bash
# omnical design ode from the command line: the seed's two designs (spec files shipped in
# datasets-synthetic/designs), the designed sensor taken by another subcommand, and bad
# input. Usage: design_test.sh OMNICAL_BINARY SOURCE_DIR
set -u
omnical=$1
source_dir=$(cd "$2" && pwd)
designs=$source_dir/datasets-synthetic/designs
source "$(dirname "${BASH_SOURCE[0]}")/harness.sh"

value() { python3 -c "import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])" "$1/design.json" "$2"; }
within() { awk -v v="$1" -v e="$2" -v t="$3" 'BEGIN { d = v - e; if (d < 0) d = -d; exit !(d <= t) }'; }

# Uniform (Sec. 3.2): phi0 = atan(d / (F0 - b)) = 25.70 deg; phi1, field vs SEED-NOTES.md.
"$omnical" design ode --spec "$designs/gaechter-uniform.yaml" --out "$work/uniform" --quiet || fail "design ode uniform exited $?"
for f in design.json profile.csv sensor.yaml law_ratio.csv law_ratio.png profile.png; do check test -s "$work/uniform/$f"; done
check within "$(value "$work/uniform" phi0_deg)" 25.7038 0.01
check within "$(value "$work/uniform" phi1_deg)" 106.5 0.1
check within "$(value "$work/uniform" fov_deg)" 80.8 0.1
# Log-polar (Sec. 3.3): phi1 = 96.4 deg; the law through the traced sensor within 1e-6.
"$omnical" design ode --spec "$designs/gaechter-logpolar.yaml" --out "$work/logpolar" --quiet || fail "design ode logpolar exited $?"
check within "$(value "$work/logpolar" phi1_deg)" 96.4 0.05
check awk -v e="$(value "$work/logpolar" max_law_error_rel)" 'BEGIN { exit !(e < 1e-6) }'
# The designed sensor is a sensor: another subcommand takes it (a panorama table).
"$omnical" remap --sensor "$work/logpolar/sensor.yaml" --view panorama --size 360x90 --infinity --format npy \
  --out "$work/maps" --quiet && check test -s "$work/maps/map_x.npy" || fail "remap of the designed sensor failed"
# Same design from options instead of a spec file.
"$omnical" design ode --law linear --focal-length-mm 12.5 --distance-mm 2000 --start-height-mm 155 --rim-limit-mm 30 \
  --rho1-mm 2.4 --gain 2000 --offset-mm -4000 --samples 2001 --out "$work/options" --quiet || fail "design ode by options exited $?"
check within "$(value "$work/options" phi1_deg)" "$(value "$work/uniform" phi1_deg)" 1e-9

# Bad input: exit 2, one line naming the cause, nothing written.
printf 'rho_mm,h_mm\n0,-4000\n1,-2000\n2,-2500\n3,2000\n' >"$work/bent.csv"
expect_error "non-monotone law" "not monotone (h does not increase) at row 3" "$work/bad" -- \
  design ode --law table --law-table "$work/bent.csv" --focal-length-mm 12.5 --distance-mm 2000 --start-height-mm 155 \
  --rim-limit-mm 30 --rho1-mm 2.4 --out "$work/bad"
expect_error "rho1 beyond the rim" "beyond the image of the rim" "$work/bad" -- \
  design ode --law linear --focal-length-mm 12.5 --distance-mm 2000 --start-height-mm 155 --rim-limit-mm 30 \
  --rho1-mm 3 --gain 2000 --offset-mm -4000 --out "$work/bad"
expect_error "folding mirror" "folds back" "$work/bad" -- \
  design ode --law linear --focal-length-mm 12.5 --distance-mm 2000 --start-height-mm 155 --rim-limit-mm 30 \
  --rho1-mm 2.4 --gain 1 --offset-mm -1e6 --out "$work/bad"
expect_error "missing spec" "file not found" "$work/bad" -- design ode --spec "$work/none.yaml" --out "$work/bad"
printf 'focal_length_mm: 12.5\ndistance_mm: 2000\nstart_height_mm: 155\nrim_limit_mm: 30\nimager: { rho1_mm: 2.4 }\nlaw: { type: cubic }\n' >"$work/typo.yaml"
expect_error "unknown law" "law.type" "$work/bad" -- design ode --spec "$work/typo.yaml" --out "$work/bad"
summary design_test
