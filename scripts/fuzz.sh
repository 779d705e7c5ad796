#!/usr/bin/env bash
# Fuzzes every parser of outside input with libFuzzer + ASan + UBSan (clang; docs/fuzzing.md):
# configures build/fuzz, builds the targets (fuzz/) and runs each on a scratch copy of its corpus
# tests/fuzz_corpus/<target>, so that the repository's corpus is never changed. Prints the executions
# and the time per target; fails on a crash, a sanitizer report, a leak, a timeout (-timeout, 10 s an
# input) or an allocation over -rss_limit_mb (2 GiB), whose input is left in build/fuzz/artifacts/
# (fix the bug, then add the input to the corpus as bad_<what>; tests/fuzz_corpus.h feeds the
# corpora to the parsers in the unit tests).
#
#   scripts/fuzz.sh [--smoke] [RUNS] [TARGET...] [-- more libFuzzer flags...]
#
# RUNS: executions per target, default 1000000; --smoke: 2000 (or 10 s) each, for CI. TARGET: e.g.
# gmsh vr_ws (default: all; --list names them). Flags starting with '-' before '--' go to libFuzzer
# too. JOBS=N build jobs (default 2).
set -euo pipefail
cd "$(dirname "$0")/.."
build=build/fuzz

runs=1000000
max_time=0
targets=()
flags=()
while [ $# -gt 0 ]; do
  case $1 in
    --smoke) runs=2000 max_time=10 ;;
    --list) list=1 ;;
    --) shift; flags+=("$@"); break ;;
    -*) flags+=("$1") ;;
    *[!0-9]*) targets+=("$1") ;;
    *) runs=$1 ;;
  esac
  shift
done

# The targets, as fuzz/CMakeLists.txt declares them.
all=()
mapfile -t all < <(sed -n 's/^vrdeform_fuzzer(\([a-z_0-9]*\) .*/\1/p' fuzz/CMakeLists.txt)
mapfile -t -O "${#all[@]}" all < <(sed -n 's/^foreach(format \(.*\))$/\1/p' fuzz/CMakeLists.txt | tr ' ' '\n')
if [ -n "${list:-}" ]; then
  printf '%s\n' "${all[@]}"
  exit 0
fi
[ ${#targets[@]} -gt 0 ] || targets=("${all[@]}")
build_targets=()
for t in "${targets[@]}"; do
  printf '%s\n' "${all[@]}" | grep -qx "$t" || { echo "fuzz.sh: no target '$t' (targets: ${all[*]})" >&2; exit 2; }
  build_targets+=("vrdeform_${t}_fuzz")
done
CC=clang CXX=clang++ cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVRDEFORM_FUZZ=ON \
  -DVRDEFORM_WERROR=ON -DVRDEFORM_BUILD_TESTS=OFF -DVRDEFORM_BUILD_BENCHMARKS=OFF -DVRDEFORM_BUILD_APPS=OFF \
  -DVRDEFORM_BUILD_RENDER=OFF >/dev/null
cmake --build "$build" --target "${build_targets[@]}" -j"${JOBS:-2}"

scratch=$(mktemp -d "${TMPDIR:-/tmp}/vrdeform_fuzz.XXXXXX")
trap 'rm -rf "$scratch"' EXIT
mkdir -p "$build/artifacts"
failed=()
summary=()
for t in "${targets[@]}"; do
  corpus=$scratch/$t
  mkdir -p "$corpus"
  cp tests/fuzz_corpus/"$t"/* "$corpus"/
  log=$build/${t}_fuzz.log
  max_len=8192
  [ "$t" = weart ] && max_len=4096
  [ "$t" = vr_http ] && max_len=12288  # past the server's 8 KiB header limit
  time_flag=()
  [ "$max_time" -gt 0 ] && time_flag=(-max_total_time="$max_time")
  start=$(date +%s.%N)
  status=0
  ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=0 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "$build/fuzz/vrdeform_${t}_fuzz" -runs="$runs" "${time_flag[@]}" -max_len=$max_len -timeout=10 \
    -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$build/artifacts/${t}-" "${flags[@]}" "$corpus" \
    >"$log" 2>&1 || status=$?
  end=$(date +%s.%N)
  if grep -qE 'ERROR: (AddressSanitizer|LeakSanitizer|UndefinedBehaviorSanitizer|libFuzzer)|runtime error:|SUMMARY: ' "$log"; then
    grep -E -A20 'ERROR: |runtime error:' "$log" | head -40
    [ "$status" -eq 0 ] && status=1
  fi
  executions=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
  seconds=$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.1f", b - a }')
  line=$(printf '%-18s %9s executions %8s s  exit %s' "$t" "${executions:-?}" "$seconds" "$status")
  echo "$line (log: $log)"
  summary+=("$line")
  [ "$status" -eq 0 ] || failed+=("$t")
done

echo
echo "fuzz: $runs runs per target$([ "$max_time" -gt 0 ] && echo " (at most ${max_time} s each)")"
printf '  %s\n' "${summary[@]}"
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: findings in ${failed[*]}: inputs in $build/artifacts/" >&2
  exit 1
fi
