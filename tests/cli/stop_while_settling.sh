#!/bin/sh
# Ctrl-C while a scene settles: `vrdeform run` (or `view`, on a display) stops within half a
# second, says where it stopped and exits with status 130.
# Usage: stop_while_settling.sh VRDEFORM MESHES_DIR SCRATCH_DIR [run|view]
set -u
vrdeform=$1 meshes=$2 dir=$3 command=${4:-run}
. "$(dirname "$0")/interrupt.sh"
mkdir -p "$dir"
cat > "$dir/slow.toml" <<TOML
format = 1
name = "slow"
settle = 300.0
[solver]
substeps = 20
[[body]]
mesh = "$meshes/sphere_coarse.obj"
scale = 0.05
[hand]
enabled = false
TOML
"$vrdeform" "$command" "$dir/slow.toml" > "$dir/out.txt" 2>&1 &
pid=$!
sleep 2
interrupt $pid "$dir/out.txt"
grep -q "stopped while settling" "$dir/out.txt" || { echo "FAIL: does not say where it stopped"; exit 1; }
echo "PASS: $command stopped in $ms ms"
