# Shared by the CLI test scripts (sourced): a temporary work directory removed on exit,
# pass/fail counters, and the summary that sets the exit status.
# The checks' Python is Debian's interpreter where it is there (scripts/common.sh builds for
# it): another python3 first on PATH may be a shim (pyenv's took 0.3 s a call against
# 0.04, 10 of cli_test.sh's 62 s).
[ -x /usr/bin/python3 ] && python3() { /usr/bin/python3 "$@"; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
passed=0
failed=0
pass() { passed=$((passed + 1)); }
fail() { failed=$((failed + 1)); echo "FAIL: $*"; }
check() { if "$@"; then pass; else fail "$*"; fi; }
# within VALUE EXPECTED TOLERANCE, below VALUE BOUND: false for anything but a finite number
# (a missing key prints nothing, a NaN in the JSON None: awk took both for 0).
within() { python3 -c 'import math, sys; v, e, t = map(float, sys.argv[1:4]); sys.exit(not (math.isfinite(v) and abs(v - e) <= t))' "$@" 2>/dev/null; }
below() { python3 -c 'import math, sys; v, b = map(float, sys.argv[1:3]); sys.exit(not (math.isfinite(v) and v < b))' "$@" 2>/dev/null; }
# summary NAME: prints the counts; its status is the script's result.
summary() {
  echo "$1: $passed passed, $failed failed"
  [ "$failed" -eq 0 ]
}
# expect_error NAME EXPECTED_SUBSTRING OUT -- ARGS...: exit 2, one stderr line with the
# substring, nothing at OUT afterwards (needs $omnical).
expect_error() {
  local name=$1 expected=$2 out=$3
  shift 4
  rm -rf "$out"
  "$omnical" "$@" >"$work/stdout" 2>"$work/stderr"
  local code=$?
  if [ "$code" -ne 2 ]; then fail "$name: exit code $code, expected 2 ($(cat "$work/stderr"))"; return; fi
  if [ "$(wc -l <"$work/stderr")" -ne 1 ]; then fail "$name: not one stderr line: $(cat "$work/stderr")"; return; fi
  if ! grep -qF -- "$expected" "$work/stderr"; then fail "$name: message lacks '$expected': $(cat "$work/stderr")"; return; fi
  if [ -e "$out" ] && [ -n "$(ls -A "$out" 2>/dev/null)" ]; then fail "$name: left output in $out"; return; fi
  pass
}
