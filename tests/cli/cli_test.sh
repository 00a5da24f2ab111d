#!/usr/bin/env bash
# End-to-end checks of the omnical command line: results of project/unproject, and the
# bad-input policy (exit code 2, exactly one line on stderr naming the file and field,
# no output file left behind). Usage: cli_test.sh OMNICAL_BINARY SOURCE_DIR
set -u
omnical=$1
source_dir=$2
sensors=$source_dir/datasets-synthetic/sensors
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
passed=0
failed=0

pass() { passed=$((passed + 1)); }
fail() { failed=$((failed + 1)); echo "FAIL: $*"; }

# expect_error NAME EXPECTED_SUBSTRING -- ARGS...: exit code 2, one stderr line containing
# the substring, and no file at $work/out.csv afterwards.
expect_error() {
  local name=$1 expected=$2
  shift 3
  rm -f "$work/out.csv"
  "$omnical" "$@" >"$work/stdout" 2>"$work/stderr"
  local code=$?
  local lines
  lines=$(wc -l <"$work/stderr")
  if [ "$code" -ne 2 ]; then fail "$name: exit code $code, expected 2"; return; fi
  if [ "$lines" -ne 1 ]; then fail "$name: $lines lines on stderr, expected 1: $(cat "$work/stderr")"; return; fi
  if ! grep -qF -- "$expected" "$work/stderr"; then fail "$name: message lacks '$expected': $(cat "$work/stderr")"; return; fi
  if ls "$work"/out.csv* >/dev/null 2>&1; then fail "$name: left an output file behind"; return; fi
  pass
}

# --- happy paths -------------------------------------------------------------------
cat >"$work/pixels.csv" <<'CSV'
# pixels of the seed SPH sensor: centre, mid-field, rim, a corner
u,v
499.5,499.5
700,450
999.5,499.5
5,5
CSV
if "$omnical" unproject --sensor "$sensors/ohte-sph.yaml" --pixels "$work/pixels.csv" --out "$work/rays.csv"; then
  statuses=$(tail -n +2 "$work/rays.csv" | cut -d, -f7 | tr '\n' ' ')
  [ "$statuses" = "ok ok ok outside_mirror " ] && pass || fail "unproject statuses: $statuses"
else
  fail "unproject exited $?"
fi

# Points 10 rim radii along the rays, projected back, land on the pixels they came from
# (the library tests bound this at 1e-6 px; through 15-digit CSV text 1e-6 px still holds).
awk -F, 'NR > 1 && $7 == "ok" { d = 439; printf "%.17g,%.17g,%.17g\n", $1 + d*$4, $2 + d*$5, $3 + d*$6 }' \
  "$work/rays.csv" >"$work/points.csv"
if "$omnical" project --sensor "$sensors/ohte-sph.yaml" --points "$work/points.csv" --out "$work/back.csv"; then
  worst=$(paste -d, <(tail -n +3 "$work/pixels.csv" | head -3) <(tail -n +2 "$work/back.csv") |
    awk -F, '{ du = $1 - $3; dv = $2 - $4; e = sqrt(du*du + dv*dv); if (e > w) w = e } END { printf "%.3g", w }')
  awk -v w="$worst" 'BEGIN { exit !(w < 1e-6) }' && pass || fail "project round trip error $worst px"
  [ -z "$(ls "$work" | grep '\.tmp\.')" ] && pass || fail "temporary file left behind"
else
  fail "project exited $?"
fi

# Standard output when --out is absent.
"$omnical" project --sensor "$sensors/ohte-edi.yaml" --points "$work/points.csv" | grep -q "^u,v,status$" && pass ||
  fail "project to stdout"

"$omnical" --help >/dev/null && "$omnical" project --help >/dev/null && "$omnical" unproject --help >/dev/null && pass ||
  fail "--help"

# --- bad input -----------------------------------------------------------------------
printf 'camera: { model: pinhole, image_size: [1000, 1000\n' >"$work/malformed.yaml"
sed 's/profile: sphere/profile: cone/' "$sensors/ohte-sph.yaml" >"$work/unknown_profile.yaml"
sed 's/A: 49/A: -49/' "$sensors/ohte-sph.yaml" >"$work/negative_radius.yaml"
sed 's/m: 180.429[0-9]*/m: -1/' "$sensors/ohte-sph.yaml" >"$work/m_inside.yaml"
printf 'X,Y,Z\n1,2,3\n4,five,6\n' >"$work/text.csv"
printf 'X,Y,Z\n1,2,3\n4,nan,6\n' >"$work/nan.csv"
printf 'X,Y\n1,2\n' >"$work/short.csv"
: >"$work/empty.csv"

expect_error missing_sensor "nope.yaml: file not found" -- project --sensor "$work/nope.yaml" --points "$work/points.csv" --out "$work/out.csv"
expect_error malformed_yaml "malformed.yaml: line" -- project --sensor "$work/malformed.yaml" --points "$work/points.csv" --out "$work/out.csv"
expect_error unknown_profile "mirror.profile: unknown profile 'cone'" -- project --sensor "$work/unknown_profile.yaml" --points "$work/points.csv" --out "$work/out.csv"
expect_error negative_radius "negative_radius.yaml: mirror.A: must be > 0" -- project --sensor "$work/negative_radius.yaml" --points "$work/points.csv" --out "$work/out.csv"
expect_error m_inside_mirror "m_inside.yaml: pose.m: must be > 0" -- project --sensor "$work/m_inside.yaml" --points "$work/points.csv" --out "$work/out.csv"
expect_error csv_text "text.csv:3: column 2: 'five' is not a number" -- project --sensor "$sensors/ohte-sph.yaml" --points "$work/text.csv" --out "$work/out.csv"
expect_error csv_nan "nan.csv:3: column 2: value is not finite" -- project --sensor "$sensors/ohte-sph.yaml" --points "$work/nan.csv" --out "$work/out.csv"
expect_error csv_short "short.csv:2: expected at least 3 columns" -- project --sensor "$sensors/ohte-sph.yaml" --points "$work/short.csv" --out "$work/out.csv"
expect_error csv_empty "empty.csv: no numeric rows" -- project --sensor "$sensors/ohte-sph.yaml" --points "$work/empty.csv" --out "$work/out.csv"
expect_error pixels_text "text.csv:3: column 2" -- unproject --sensor "$sensors/ohte-sph.yaml" --pixels "$work/text.csv" --out "$work/out.csv"
expect_error missing_option "--points is required" -- project --sensor "$sensors/ohte-sph.yaml"
expect_error unknown_command "" -- frobnicate
expect_error unwritable_output "cannot create output file" -- project --sensor "$sensors/ohte-sph.yaml" --points "$work/points.csv" --out "/nonexistent-dir/out.csv"

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
