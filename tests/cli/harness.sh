# Shared by the CLI test scripts (sourced): a temporary work directory removed on exit,
# pass/fail counters, and the summary that sets the exit status.
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
passed=0
failed=0
pass() { passed=$((passed + 1)); }
fail() { failed=$((failed + 1)); echo "FAIL: $*"; }
check() { if "$@"; then pass; else fail "$*"; fi; }
# summary NAME: prints the counts; its status is the script's result.
summary() {
  echo "$1: $passed passed, $failed failed"
  [ "$failed" -eq 0 ]
}
