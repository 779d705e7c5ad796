#!/bin/sh
# Ctrl-C in `vrdeform bench`: it stops within half a second, prints the tables of the parts it
# finished (not the one it was in), says where it stopped and exits with status 130.
# Usage: stop_bench.sh VRDEFORM SCRATCH_DIR
set -u
vrdeform=$1 dir=$2
. "$(dirname "$0")/interrupt.sh"
mkdir -p "$dir"
rm -f "$dir/out.txt" "$dir/err.txt"  # a last run's would match before this one writes
touch "$dir/err.txt"
"$vrdeform" bench --frames 10 --only table3 loop > "$dir/out.txt" 2> "$dir/err.txt" &
pid=$!
tries=0
until grep -q "bench \[2/2\]" "$dir/err.txt"; do  # into the real-time loop, a 2 s part
  tries=$((tries + 1))
  [ $tries -le 1200 ] || { kill $pid; echo "FAIL: the loop part never started"; exit 1; }
  sleep 0.05
done
sleep 0.5
interrupt $pid "$dir/out.txt" "$dir/err.txt"
grep -q "bench: stopped during the real-time loop (1 of 2 parts done)" "$dir/err.txt" ||
  { echo "FAIL: does not say where it stopped"; exit 1; }
grep -q "^Table 3" "$dir/out.txt" || { echo "FAIL: the finished parts' tables are missing"; exit 1; }
if grep -q "real-time loop" "$dir/out.txt"; then echo "FAIL: the stopped part's table is printed"; exit 1; fi
echo "PASS: stopped in $ms ms"
