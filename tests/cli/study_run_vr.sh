#!/bin/sh
# `vrdeform study run --vr` as a dry run (--autopilot) with a (fake) WEART glove: participant 1
# walks both conditions on the VR page's server (no browser: the scenes' scripted hands poke and
# the autopilot answers); each trial ends when the poke lets go of the liver; condition A's force
# and condition B's baseline reach the glove's index thimble, and every thimble is stopped at the end.
# Usage: study_run_vr.sh VRDEFORM FAKE_WEART SCRATCH_DIR
set -u
vrdeform=$1 fake=$2 dir=$3
rm -rf "$dir"
mkdir -p "$dir"
fail() { echo "FAIL: $*"; exit 1; }
cat > "$dir/study.toml" <<TOML
format = 1
name = "vr dry"
trials = 1
rest = 600
[[condition]]
name = "A"
scene = "liver"
[[condition]]
name = "B"
scene = "liver"
force = "baseline"
[[task]]
name = "poke"
instructions = "Press the liver with the index finger."
seconds = 8
end = "release"
[[question]]
id = "H1"
dimension = "haptic"
text = "The force grew as I pressed."
[[comparison]]
id = "D1"
text = "Which felt more natural?"
TOML
. "$(dirname "$0")/fake_weart.sh"
start_fake "$fake" "$dir"
data=$dir/data
"$vrdeform" study run "$dir/study.toml" "$data" --participant 1 --vr --port 0 --autopilot --weart "127.0.0.1:$fake_port" \
  > "$dir/P1.txt" 2>&1 || { cat "$dir/P1.txt"; fail "exit status $?"; }
stop_fake
grep -q "serving on http://127.0.0.1:" "$dir/P1.txt" || { cat "$dir/P1.txt"; fail "no address printed"; }
grep -q "P1: done" "$dir/P1.txt" || { cat "$dir/P1.txt"; fail "P1 not done"; }
# The experimenter follows each step at the console, with the condition's name.
grep -q "^P1: Part 2 of 2: poke, trial 1 of 1 \[condition B\] (running)" "$dir/P1.txt" ||
  { cat "$dir/P1.txt"; fail "the steps are not printed"; }
[ "$(cat "$data/P1/answers.csv")" = "$(printf 'condition,item,answer\nA,H1,4\nB,H1,4')" ] ||
  fail "answers: $(cat "$data/P1/answers.csv")"
for t in 1 2; do
  record=$data/P1/trials/$t-1-1/trial.json
  grep -q '"ended_by": "release"' "$record" || fail "trial $t was not ended by the release: $(cat "$record")"
  grep -q ",touch,index" "$data/P1/trials/$t-1-1/events.csv" || fail "trial $t: no touch in events.csv"
done
grep -q '"force": "baseline"' "$data/P1/trials/2-1-1/trial.json" || fail "the second condition is not B"
grep -Eq "force RIGHT INDEX 0\.[0-9]*[1-9]" "$dir/fake.log" || { cat "$dir/fake.log"; fail "no index force reached the glove"; }
released
echo "PASS: P1 walked both conditions on the VR page's server; the glove got the forces and was released"
