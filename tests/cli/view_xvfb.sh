#!/bin/sh
# The desktop viewer end to end under a virtual X server: `vrdeform view liver --frames N
# --screenshot FILE` opens its window, draws N frames, writes the screenshot and exits 0; the
# screenshot shows the body in its middle. Xvfb is required (CI installs it): no skipping.
# Usage: view_xvfb.sh VRDEFORM PNG_CHECK OUT_PREFIX
set -eu
vrdeform=$1 check=$2 out=$3
rm -f "$out.png"
command -v xvfb-run >/dev/null || { echo "FAIL: xvfb-run not found (scripts/install-deps.sh installs xvfb)"; exit 1; }
xvfb-run -a -s "-screen 0 1280x1024x24" "$vrdeform" view liver --frames 30 --width 800 --height 600 \
  --screenshot "$out.png" || { echo "FAIL: vrdeform view exited with $?"; exit 1; }
[ -s "$out.png" ] || { echo "FAIL: no screenshot"; exit 1; }
"$check" "$out.png" || { echo "FAIL: the body is not visible in $out.png"; exit 1; }
echo "PASS: viewer drew 30 frames and its screenshot shows the body"
