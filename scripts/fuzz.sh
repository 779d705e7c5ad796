#!/usr/bin/env bash
# Fuzzes the WEART protocol parsers with libFuzzer + ASan + UBSan (clang): configures build/fuzz,
# builds vrdeform_weart_fuzz and runs it on a scratch copy of tests/fuzz_corpus/weart, so that the
# repository's corpus is never changed. Prints the number of executions and the time taken; fails on
# a crash, a sanitizer report or a leak, whose input is left in build/fuzz/artifacts/ (fix the bug,
# then add the input to the corpus as bad_<what> or ok_<side>_<what>; see tests/test_weart_protocol.cpp).
#
#   scripts/fuzz.sh [RUNS] [more libFuzzer flags...]     RUNS defaults to 1000000; JOBS=2 build jobs
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:-1000000}
[ $# -gt 0 ] && shift
build=build/fuzz

CC=clang CXX=clang++ cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVRDEFORM_FUZZ=ON \
  -DVRDEFORM_WERROR=ON -DVRDEFORM_BUILD_TESTS=OFF -DVRDEFORM_BUILD_BENCHMARKS=OFF -DVRDEFORM_BUILD_APPS=OFF >/dev/null
cmake --build "$build" --target vrdeform_weart_fuzz -j"${JOBS:-2}"

scratch=$(mktemp -d "${TMPDIR:-/tmp}/vrdeform_weart_corpus.XXXXXX")
trap 'rm -rf "$scratch"' EXIT
cp tests/fuzz_corpus/weart/* "$scratch"/
mkdir -p "$build/artifacts"
log=$build/weart_fuzz.log

start=$(date +%s.%N)
status=0
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  "$build/fuzz/vrdeform_weart_fuzz" -runs="$runs" -max_len=4096 -print_final_stats=1 \
  -artifact_prefix="$build/artifacts/" "$@" "$scratch" >"$log" 2>&1 || status=$?
end=$(date +%s.%N)

grep -E '^(#[0-9]+ +DONE|Done |stat::)' "$log" || true
if grep -qE 'ERROR: (AddressSanitizer|LeakSanitizer|UndefinedBehaviorSanitizer|libFuzzer)|runtime error:|SUMMARY: ' "$log"; then
  grep -E -A20 'ERROR: |runtime error:' "$log" | head -40
  [ "$status" -eq 0 ] && status=1
fi
executions=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
seconds=$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.1f", b - a }')
echo "weart fuzz: ${executions:-?} executions in ${seconds} s, exit status ${status} (log: ${log})"
exit "$status"
