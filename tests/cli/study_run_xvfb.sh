#!/bin/sh
# `vrdeform study run` in the desktop viewer under a virtual X server, as a dry run (--autopilot):
# two participants walk the practice, their conditions in their Latin-square orders, the
# questionnaires and the final questions into DATA/P1 and DATA/P2, which `study analyse` reads; a
# third, whose trials end when the scripted poke lets go of the liver (end = "release"), is stopped
# with Ctrl-C after their first trial and goes on from there, keeping it.
# Usage: study_run_xvfb.sh VRDEFORM SCRATCH_DIR   (run under xvfb-run)
set -u
vrdeform=$1 dir=$2
. "$(dirname "$0")/interrupt.sh"
rm -rf "$dir"
mkdir -p "$dir"
fail() { echo "FAIL: $*"; exit 1; }
cat > "$dir/dry.toml" <<TOML
format = 1
name = "dry"
trials = 1
rest = 600
[practice]
seconds = 0.2
[[condition]]
name = "A"
scene = "liver"
[[condition]]
name = "B"
scene = "liver"
force = "baseline"
device = "osc"           # the discard port: sent, never read
osc = "127.0.0.1:9"
[[task]]
name = "poke"
instructions = "Press the liver with the index finger."
seconds = 1
[[question]]
id = "H1"
dimension = "haptic"
text = "The force grew as I pressed."
[[comparison]]
id = "D1"
text = "Which felt more natural?"
[[free_text]]
id = "F1"
text = "What did you feel?"
TOML
data=$dir/data
for k in 1 2; do
  "$vrdeform" study run "$dir/dry.toml" "$data" --participant $k --autopilot > "$dir/P$k.txt" 2>&1 ||
    { cat "$dir/P$k.txt"; fail "P$k: exit status $?"; }
  grep -q "P$k: done" "$dir/P$k.txt" || { cat "$dir/P$k.txt"; fail "P$k not done"; }
  for f in practice/forces.csv trials/1-1-1/forces.csv trials/2-1-1/trial.json questionnaires/final.json answers.csv \
           comparisons.csv free_text.json; do
    [ -s "$data/P$k/$f" ] || fail "P$k/$f missing"
  done
  # 60 steps of 1/60 s, each a row of the signal (and the header, and the release's row of zeros).
  grep -q '"steps": 60' "$data/P$k/trials/1-1-1/trial.json" || fail "P$k: the trial did not run its 60 steps"
  [ "$(wc -l < "$data/P$k/trials/1-1-1/forces.csv")" -eq 62 ] || fail "P$k: forces.csv does not have 60 rows"
done
grep -q '"order": \[ *"A", *"B"' "$data/P1/participant.json" || tr -d '\n ' < "$data/P1/participant.json" |
  grep -q '"order":\["A","B"\]' || fail "P1's order is not A, B"
tr -d '\n ' < "$data/P2/participant.json" | grep -q '"order":\["B","A"\]' || fail "P2's order is not B, A"
grep -q '"force": "baseline"' "$data/P2/trials/1-1-1/trial.json" || fail "P2 did not meet B first"
grep -q '"device": "osc"' "$data/P2/trials/1-1-1/trial.json" || fail "B's device is not OSC"
[ "$(cat "$data/P2/answers.csv")" = "$(printf 'condition,item,answer\nB,H1,4\nA,H1,4')" ] ||
  fail "P2's answers: $(cat "$data/P2/answers.csv")"
"$vrdeform" study analyse "$dir/dry.toml" "$data" > "$dir/analyse.txt" 2>&1 || { cat "$dir/analyse.txt"; fail "analyse"; }
[ -s "$data/analysis/report.md" ] || fail "no report"
# Done is done: no window, nothing run again.
"$vrdeform" study run "$dir/dry.toml" "$data" --participant 1 --autopilot > "$dir/again.txt" 2>&1 || fail "P1 again"
grep -q "3 trials kept" "$dir/again.txt" || { cat "$dir/again.txt"; fail "P1's trials not kept"; }

# Stopped after the first trial, resumed: that trial is kept as it was.
sed 's/seconds = 1$/seconds = 8\nend = "release"/' "$dir/dry.toml" > "$dir/long.toml"
"$vrdeform" study run "$dir/long.toml" "$data" --participant 3 --autopilot > "$dir/P3.txt" 2>&1 &
pid=$!
first=$data/P3/trials/1-1-1/trial.json
for i in $(seq 600); do [ -f "$first" ] && break; sleep 0.1; done
[ -f "$first" ] || { kill $pid; fail "P3's first trial did not finish in 60 s"; }
kept=$(cat "$first")
interrupt $pid "$dir/P3.txt"
grep -q "P3 stopped before the end" "$dir/P3.txt" || fail "no word on how to go on"
"$vrdeform" study run "$dir/long.toml" "$data" --participant 3 --autopilot > "$dir/P3b.txt" 2>&1 ||
  { cat "$dir/P3b.txt"; fail "P3's resume"; }
grep -q "2 trials kept" "$dir/P3b.txt" || { cat "$dir/P3b.txt"; fail "P3's finished trials not kept"; }
[ "$(cat "$first")" = "$kept" ] || fail "P3's first trial was run again"
[ -s "$data/P3/questionnaires/final.json" ] || fail "P3 not done"
# The liver's poke lets go at 3-4 s: the trial ended half a second after, not at its 8 s (480 steps).
for t in 1 2; do
  record=$data/P3/trials/$t-1-1/trial.json
  grep -q '"ended_by": "release"' "$record" || fail "P3's trial $t was not ended by the release: $(cat "$record")"
  steps=$(sed -n 's/.*"steps": \([0-9]*\).*/\1/p' "$record")
  [ "$steps" -ge 180 ] && [ "$steps" -le 300 ] || fail "P3's trial $t ran $steps steps, not 180..300"
  grep -q ",touch,index" "$data/P3/trials/$t-1-1/events.csv" || fail "P3's trial $t: no touch in events.csv"
  grep -q "^contact,total," "$data/P3/trials/$t-1-1/latency.csv" || fail "P3's trial $t: no latency.csv"
done
echo "PASS: P1 and P2 walked the study in their orders; P3 stopped after a trial and went on from there"
