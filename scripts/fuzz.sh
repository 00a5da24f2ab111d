#!/usr/bin/env bash
# Fuzzes every parser of a user file with libFuzzer (issues 8, 21): builds tests/fuzz with
# clang under ASan + UBSan (build/fuzz, OMNICAL_FUZZ=ON), makes a seed corpus from
# datasets-synthetic, small outputs of omnical itself (detections, maps, a designed
# profile) and the committed minimized corpora (tests/fuzz/corpus/<target>), runs each
# target for SECONDS (default 60) or for N executions (--runs N), as many targets at once
# as there are cores, and writes docs/fuzzing.md with the executions each survived.
# --update-corpus then replaces tests/fuzz/corpus/<target> with this run's corpus and the
# committed one merged and minimized (libFuzzer -merge=1: the fewest inputs that keep
# every feature reached; the generated seeds stay out, they are made anew each run).
# A target that crashes, times out (20 s) or runs out of memory fails the script after the
# others have run; its row in docs/fuzzing.md says so and names the reproducer under
# build/fuzz/crashes/ (rerun: OMNICAL_FUZZ_TARGET=<target> build/fuzz/tests/fuzz/omnical_fuzz
# FILE), and its committed corpus is left as it was. Each run starts from the seeds and
# committed corpora, not from the last run's build/fuzz/corpus. --targets a,b runs only
# those (after a fix in one parser): the table keeps the other targets' rows from their
# last run (build/fuzz/results/<target>, each row dated). --report-only writes the table
# (and, with --update-corpus, merges the corpora) from the last run's results, fuzzing
# nothing.
# Usage: scripts/fuzz.sh [SECONDS | --runs N] [--targets T1,T2] [--update-corpus] [--report-only]
set -euo pipefail
seconds=60
runs=""
update_corpus=0
chosen=""
report_only=0
while [ $# -gt 0 ]; do
  case $1 in
    --runs) runs=$2; shift 2 ;;
    --update-corpus) update_corpus=1; shift ;;
    --targets) chosen=$2; shift 2 ;;
    --report-only) report_only=1; shift ;;
    *) seconds=$1; shift ;;
  esac
done
omnical_build_kind=fuzz
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
omnical_packages+=(clang libclang-rt-14-dev)
install_dependencies
CC=clang CXX=clang++ cmake -S "$omnical_root" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Fuzz -DCMAKE_CXX_FLAGS_FUZZ="-O1 -g" \
  -DOMNICAL_FUZZ=ON -DOMNICAL_BUILD_TESTS=OFF -DOMNICAL_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$build_dir" -j "$jobs" --target omnical_fuzz omnical
fuzzer=$build_dir/tests/fuzz/omnical_fuzz
omnical=$build_dir/tools/omnical
data=$omnical_root/datasets-synthetic
export OMNICAL_FUZZ_DATA=$data ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1

seeds=$build_dir/seeds
rm -rf "$seeds"
mkdir -p "$seeds"/{sensor_yaml,scene_yaml,target_yaml,design_spec_yaml,detections_json,maps_json,maps_yml,points_csv,profile_csv}
cp "$data"/sensors/*.yaml "$seeds/sensor_yaml/"
cp "$data"/scenes/*.yaml "$seeds/scene_yaml/"
cp "$data"/targets/*.yaml "$seeds/target_yaml/"
cp "$data"/designs/*.yaml "$seeds/design_spec_yaml/"
head -40 "$data/pixels/grid-25px.csv" >"$seeds/points_csv/grid.csv"
printf 'X,Y,Z\n300,40,100\n-120.5,80,-3e2\n' >"$seeds/points_csv/points.csv"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$omnical" -q design ode --spec "$data/designs/gaechter-logpolar.yaml" --samples 100 --out "$work/design"
cp "$work/design/profile.csv" "$seeds/profile_csv/"
cp "$work/design/sensor.yaml" "$seeds/sensor_yaml/designed.yaml"
"$omnical" -q remap --sensor "$data/sensors/ohte-sph.yaml" --view panorama --size 16x4 --infinity --format opencv --out "$work/maps"
cp "$work/maps/maps.json" "$seeds/maps_json/"
gunzip -c "$work/maps/maps.yml.gz" >"$seeds/maps_yml/maps.yml"
# A small detections file: the first image's first corners of a real detection run.
"$omnical" -q detect --target "$data/targets/aprilgrid-6x6-30mm.yaml" --images "$data/rendered/ohte-sph-near" \
  --out "$work/detections.json"
python3 - "$work/detections.json" "$seeds/detections_json/detections.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
d["images"] = d["images"][:1]
d["images"][0]["corners"] = d["images"][0]["corners"][:6]
json.dump(d, open(sys.argv[2], "w"), indent=1)
PY

committed=$omnical_root/tests/fuzz/corpus
all_targets=(sensor_yaml scene_yaml target_yaml design_spec_yaml detections_json maps_json maps_yml points_csv profile_csv)
targets=("${all_targets[@]}")
if [ -n "$chosen" ]; then
  IFS=, read -r -a targets <<<"$chosen"
  for target in "${targets[@]}"; do
    [[ " ${all_targets[*]} " == *" $target "* ]] || { echo "omnical: --targets: unknown target '$target' (${all_targets[*]})" >&2; exit 2; }
  done
fi
for target in "${targets[@]}"; do
  [ -d "$committed/$target" ] && cp "$committed/$target"/* "$seeds/$target/" 2>/dev/null || true
done
if [ -n "$runs" ]; then limit=(-runs="$runs"); limit_text="$runs executions"; else limit=(-max_total_time="$seconds"); limit_text="$seconds s"; fi

mkdir -p "$build_dir/crashes" "$build_dir/corpus" "$build_dir/results"
if [ "$report_only" = 0 ]; then
  for target in "${targets[@]}"; do
    rm -rf "${build_dir:?}/corpus/$target" "$build_dir/results/$target" "$build_dir/results/$target.failed"
  done
fi
# One target: fuzz, then write "runs seconds corpus_size seeds date" to results/<target>
# (nothing on a crash).
fuzz_target() {
  local target=$1 corpus=$build_dir/corpus/$1 log=$build_dir/$1.log start=$SECONDS
  mkdir -p "$corpus"
  if ! OMNICAL_FUZZ_TARGET=$target "$fuzzer" "${limit[@]}" -max_len=16384 -rss_limit_mb=4096 -timeout=20 \
      -print_final_stats=1 -artifact_prefix="$build_dir/crashes/$target-" "$corpus" "$seeds/$target" >"$log" 2>&1; then
    return 1
  fi
  local done_runs
  done_runs=$(sed -n 's/^stat::number_of_executed_units: *\([0-9]*\).*/\1/p' "$log")
  [ -n "$done_runs" ] || return 1  # no final statistics: not a clean finish
  echo "$done_runs $((SECONDS - start)) $(ls "$corpus" | wc -l) $(ls "$seeds/$target" | wc -l) $(date -u +%Y-%m-%d)" \
    >"$build_dir/results/$target"
}
if [ "$report_only" = 0 ]; then
  echo "fuzzing ${#targets[@]} targets for $limit_text each, $jobs at a time (logs: $build_dir/<target>.log)"
  for target in "${targets[@]}"; do
    while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do wait -n || true; done
    fuzz_target "$target" &
  done
  wait
fi
# A target without results: record what stopped it, from its log and artifact, for the table.
failed=()
for target in "${targets[@]}"; do
  [ -s "$build_dir/results/$target" ] && continue
  log=$build_dir/$target.log
  [ -s "$log" ] || continue
  failed+=("$target")
  echo "omnical: $target crashed or stopped early; see $log and $build_dir/crashes/" >&2
  tail -30 "$log" >&2
  artifact=$(ls -t "$build_dir/crashes/$target-"* 2>/dev/null | head -1 || true)
  case $artifact in
    *timeout*) kind=timeout ;;
    *oom*) kind=out-of-memory ;;
    "") kind=stopped ;;
    *) kind=crash ;;
  esac
  units=$(sed -n 's/^stat::number_of_executed_units: *\([0-9]*\).*/\1/p' "$log")
  echo "$kind ${units:-?} ${artifact:+build/fuzz/crashes/$(basename "$artifact")} $(date -u -r "$log" +%Y-%m-%d)" \
    >"$build_dir/results/$target.failed"
done

rows=()
for target in "${all_targets[@]}"; do
  if [ ! -s "$build_dir/results/$target" ] && [ -s "$build_dir/results/$target.failed" ]; then
    read -r kind units artifact run_date <"$build_dir/results/$target.failed"
    rows+=("| \`$target\` | | **$kind** after $units | | | | $run_date | **$kind**: \`$artifact\` |")
    continue
  fi
  if [ ! -s "$build_dir/results/$target" ]; then
    rows+=("| \`$target\` | | not run | | | | | |")
    continue
  fi
  read -r done_runs took corpus_size seed_count run_date <"$build_dir/results/$target"
  rows+=("| \`$target\` | $seed_count | $done_runs | $took | $((done_runs / (took > 0 ? took : 1))) | $corpus_size | $run_date | no crash |")
done

{
  echo "# Fuzzing the parsers (generated by scripts/fuzz.sh; do not edit)"
  echo
  echo "libFuzzer (clang $(clang --version | sed -n 's/.*version \([0-9.]*\).*/\1/p;q')) with ASan + UBSan over omnical's"
  echo "parsers of user files (\`tests/fuzz/fuzz_parsers.cc\`); the input is written to a file and"
  echo "read as the CLI reads it; refusing it with \`InputError\` is the only accepted answer."
  echo "Seeds: datasets-synthetic's files, small outputs of omnical itself and the committed minimized"
  echo "corpora (\`tests/fuzz/corpus/<target>\`). Last run: \`scripts/fuzz.sh $([ "$report_only" = 1 ] && echo "--report-only" || echo "${runs:+--runs }${runs:-$seconds}${chosen:+ --targets $chosen}")\`"
  echo "on $(date -u +%Y-%m-%d), $(nproc) cores, $jobs targets at a time; a row of a target it did not run is that target's last run's."
  echo
  echo "| target | seeds | executions survived | seconds | executions/s | corpus after | run on | result |"
  echo "| --- | --- | --- | --- | --- | --- | --- | --- |"
  printf '%s\n' "${rows[@]}"
} >"$omnical_root/docs/fuzzing.md.tmp"
mv "$omnical_root/docs/fuzzing.md.tmp" "$omnical_root/docs/fuzzing.md"
echo "omnical: docs/fuzzing.md written"

if [ "$update_corpus" = 1 ]; then
  for target in "${targets[@]}"; do
    [ -s "$build_dir/results/$target" ] || continue  # a failed target's corpus stays as it was
    merged=$build_dir/merged/$target
    rm -rf "$merged" && mkdir -p "$merged" "$committed/$target" "$build_dir/corpus/$target"
    OMNICAL_FUZZ_TARGET=$target "$fuzzer" -merge=1 -max_len=16384 -rss_limit_mb=4096 -timeout=20 \
      "$merged" "$build_dir/corpus/$target" "$committed/$target" >"$build_dir/$target.merge.log" 2>&1
    # Replaced only by a merge that produced something.
    if [ -n "$(ls -A "$merged")" ]; then
      rm -rf "${committed:?}/$target.new" && cp -r "$merged" "$committed/$target.new"
      rm -rf "${committed:?}/$target" && mv "$committed/$target.new" "$committed/$target"
    fi
    echo "$target: $(ls "$committed/$target" | wc -l) inputs, $(du -sk "$committed/$target" | cut -f1) KB in tests/fuzz/corpus/$target"
  done
fi
[ ${#failed[@]} -eq 0 ] || { echo "omnical: failed: ${failed[*]}" >&2; exit 1; }
