#!/bin/sh
# End to end with a (fake) glove: the fake middleware closes the hand over 1 s; `vrdeform ARGS...
# --weart` (touch or run on the liver) must press it, send a force to a thimble of FINGERS (a
# regular expression such as INDEX; `-` for none: `serve` has no viewer moving the hand), and
# leave every thimble stopped when it ends. E2E_SECONDS (default 2.5): how long the command runs.
# Usage: weart_e2e.sh VRDEFORM FAKE_WEART SCRATCH_DIR FINGERS ARGS...
set -eu
vrdeform=$1 fake=$2 dir=$3 fingers=$4
shift 4
mkdir -p "$dir"
. "$(dirname "$0")/fake_weart.sh"
printf '# t thumb index middle\n0 0 0 0\n1 0.9 0.9 0.9\n' > "$dir/close.script"
start_fake "$fake" "$dir" --script "$dir/close.script"
"$vrdeform" "$@" --weart "127.0.0.1:$fake_port" --seconds "${E2E_SECONDS:-2.5}"
stop_fake
echo "--- fake middleware log:"; cat "$dir/fake.log"
grep -q 'StartFromClient' "$dir/fake.log" || { echo "FAIL: no StartFromClient"; exit 1; }
if [ "$fingers" != "-" ]; then
  grep -Eq "force RIGHT ($fingers) 0\.[0-9]*[1-9]" "$dir/fake.log" || { echo "FAIL: no $fingers force reached the glove"; exit 1; }
fi
grep -q 'StopFromClient' "$dir/fake.log" || { echo "FAIL: no StopFromClient"; exit 1; }
released
echo "PASS: forces sent, every thimble stopped at the end"
