#!/usr/bin/env bash
# omnical design from the command line. ode: the seed's two designs (spec files shipped in
# datasets-synthetic/designs); fit: Table 1 of Ohte & Tsuzuki (printed to 4 digits); the
# designed sensors taken by other subcommands; the workshop drawing; bad input. Usage: design_test.sh OMNICAL_BINARY SOURCE_DIR
set -u
omnical=$1
source_dir=$(cd "$2" && pwd)
designs=$source_dir/datasets-synthetic/designs
source "$(dirname "${BASH_SOURCE[0]}")/harness.sh"

# value DIR KEY[.KEY...]: a number from DIR/design.json.
value() {
  python3 -c "import json,sys
v = json.load(open(sys.argv[1]))
for k in sys.argv[2].split('.'): v = v[k]
print(v)" "$1/design.json" "$2"
}

# Uniform (Sec. 3.2): phi0 = atan(d / (F0 - b)) = 25.70 deg; phi1, field vs SEED-NOTES.md.
"$omnical" design ode --spec "$designs/gaechter-uniform.yaml" --out "$work/uniform" --quiet || fail "design ode uniform exited $?"
for f in design.json profile.csv sensor.yaml law_ratio.csv law_ratio.png profile.png profile_drawing.svg profile_drawing.png; do check test -s "$work/uniform/$f"; done
check within "$(value "$work/uniform" phi0_deg)" 25.7038 0.01
check within "$(value "$work/uniform" phi1_deg)" 106.5 0.1
check within "$(value "$work/uniform" fov_deg)" 80.8 0.1
# The law through the traced sensor from 0.1 % of the field (the vertex is a cone point).
check below "$(value "$work/uniform" max_law_error_rel)" 1e-6
# Log-polar (Sec. 3.3): phi1 = 96.4 deg; the law through the traced sensor within 1e-6.
"$omnical" design ode --spec "$designs/gaechter-logpolar.yaml" --out "$work/logpolar" --quiet || fail "design ode logpolar exited $?"
check within "$(value "$work/logpolar" phi1_deg)" 96.4 0.05
check below "$(value "$work/logpolar" max_law_error_rel)" 1e-6
# The designed sensor is a sensor: another subcommand takes it (a panorama table).
"$omnical" remap --sensor "$work/logpolar/sensor.yaml" --view panorama --size 360x90 --infinity --format npy \
  --out "$work/maps" --quiet && check test -s "$work/maps/map_x.npy" || fail "remap of the designed sensor failed"
# Same design from options instead of a spec file.
"$omnical" design ode --law linear --focal-length-mm 12.5 --distance-mm 2000 --start-height-mm 155 --rim-limit-mm 30 \
  --rho1-mm 2.4 --gain 2000 --offset-mm -4000 --samples 2001 --out "$work/options" --quiet || fail "design ode by options exited $?"
check within "$(value "$work/options" phi1_deg)" "$(value "$work/uniform" phi1_deg)" 1e-9

# The drawing is well-formed SVG with the diameter (2 t1 = 60 mm) and the uniform design's
# cone point (the ODE's slope at the axis) written on it.
check python3 - "$work/uniform/profile_drawing.svg" <<'PY'
import sys, xml.etree.ElementTree as ET
texts = [t.text for t in ET.parse(sys.argv[1]).getroot().iter("{http://www.w3.org/2000/svg}text")]
sys.exit(0 if "DIA 60.000" in texts and any(t.startswith("The vertex is a cone point") for t in texts) else 1)
PY

# design fit against Table 1: the sphere and the hyperboloid are fixed by the two rim
# targets (half a unit of the 4th printed digit); the equidistant polynomial must be more
# linear than the paper's coefficients (ohte-edi.yaml, measured the same way).
sensors=$source_dir/datasets-synthetic/sensors
"$omnical" design fit --profile sphere --rim-omega 135 --rim-theta 12 --out "$work/sph" --quiet || fail "design fit sphere exited $?"
check within "$(value "$work/sph" parameters.normalised.A)" 1.138 5e-4
check within "$(value "$work/sph" parameters.normalised.m)" 4.110 5e-4
check within "$(value "$work/sph" parameters.mm.A_mm)" "$(awk 'BEGIN { print 1.138 * 43.9 }')" 0.03
"$omnical" design fit --profile hyperboloid --characteristic svp --out "$work/svp" --quiet || fail "design fit hyperboloid exited $?"
check within "$(value "$work/svp" parameters.normalised.A)" 0.7407 5e-5
check within "$(value "$work/svp" parameters.normalised.B)" 1.698 5e-4
check below "$(value "$work/svp" achieved.viewpoint_spread_mm)" 1e-9
"$omnical" design fit --profile polynomial --characteristic equidistant --compare "$sensors/ohte-edi.yaml"   --out "$work/edi" --quiet || fail "design fit polynomial exited $?"
for f in design.json profile.csv sensor.yaml characteristic.csv characteristic.png profile_drawing.svg profile_drawing.png; do
  check test -s "$work/edi/$f"
done
fitted=$(value "$work/edi" achieved.equidistant_max_px)
table1=$(value "$work/edi" compared.equidistant_max_px)
echo "equidistant non-linearity: fitted $fitted px, Table 1 $table1 px (rim at 500 px)"
check below "$fitted" "$table1"
check within "$(value "$work/edi" achieved.rim_omega_deg)" 135 1e-9
# The fitted sensor is a sensor: characterize and project take it.
"$omnical" characterize --sensor "$work/edi/sensor.yaml" --out "$work/edi-char" --quiet || fail "characterize of the fitted sensor failed"
check test -s "$work/edi-char/characteristics.csv"

# Bad input: exit 2, one line naming the cause, nothing written.
expect_error "Omega below Theta" "rim-omega" "$work/bad" -- design fit --profile sphere --rim-omega 10 --out "$work/bad"
expect_error "NaN target" "argument 'nan' is not a finite number" "$work/bad" -- design fit --profile sphere --rim-theta nan --out "$work/bad"
expect_error "sphere has no freedom" "a sphere is fixed by the two rim targets" "$work/bad" -- \
  design fit --profile sphere --characteristic equidistant --out "$work/bad"
expect_error "lens inside the mirror" "lens at m = -" "$work/bad" -- \
  design fit --profile sphere --rim-omega 175 --rim-theta 70 --out "$work/bad"
expect_error "missing compare file" "none.yaml" "$work/bad" -- \
  design fit --profile polynomial --compare "$work/none.yaml" --out "$work/bad"
expect_error "tilted compare sensor" "tilted or decentred" "$work/bad" -- \
  design fit --profile polynomial --compare "$sensors/ohte-sph-misaligned.yaml" --out "$work/bad"

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
