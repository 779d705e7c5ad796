#!/bin/sh
# `vrdeform touch MESH` is the scene of the mesh alone with the standard poke: the same scene
# written as a file and run with `vrdeform run` gives the same per-step CSV, bit for bit (all but
# the wall clock). And a recording replays from a new path when its mesh moved, checked by the
# mesh's fingerprint.
# Usage: touch_is_a_scene.sh VRDEFORM MESHES_DIR SCRATCH_DIR
set -u
vrdeform=$1 meshes=$2 dir=$3
mkdir -p "$dir"
fail() { echo "FAIL: $1"; exit 1; }
cat > "$dir/liver_poke.toml" <<TOML
seconds = 4.5
[[body]]
mesh = "$meshes/liver_coarse.obj"
scale = 0.001
tets = 600
[[hand.action]]
type = "poke"
approach = 2.0
hold = 1.0
release = 1.0
depth = 0.009
TOML
"$vrdeform" touch "$meshes/liver_coarse.obj" --scale 0.001 --tets 600 --forces "$dir/touch.csv" \
  --record "$dir/touch.session" > "$dir/touch.txt" 2>&1 || fail "touch: $(tail -3 "$dir/touch.txt")"
"$vrdeform" run "$dir/liver_poke.toml" --forces "$dir/run.csv" > "$dir/run.txt" 2>&1 || fail "run: $(tail -3 "$dir/run.txt")"
cut -d, -f3 --complement "$dir/touch.csv" > "$dir/touch.cut"
cut -d, -f3 --complement "$dir/run.csv" > "$dir/run.cut"
cmp -s "$dir/touch.cut" "$dir/run.cut" || fail "touch and the same scene run differ: $(diff "$dir/touch.cut" "$dir/run.cut" | head -4)"
rows=$(($(wc -l < "$dir/touch.cut") - 2))  # less the header and the release's row of zeros
[ "$rows" -eq 270 ] || fail "$rows steps, not 270 (4.5 s at 60 Hz)"
awk -F, 'NR > 1 && $17 > 0.5 { pressed = 1 } END { exit !pressed }' "$dir/touch.csv" || fail "the poke never pushed 0.5 N"

# The mesh moves: the replay says so and takes the new path; another mesh there is refused.
cp "$meshes/liver_coarse.obj" "$dir/moved.obj"
sed "s|$meshes/liver_coarse.obj|$dir/gone.obj|" "$dir/touch.session" > "$dir/moved.session"
"$vrdeform" touch --replay "$dir/moved.session" > "$dir/gone.txt" 2>&1
[ $? -eq 2 ] && grep -q "gone.obj is not there: if it moved, give its new path" "$dir/gone.txt" ||
  fail "a moved mesh: $(cat "$dir/gone.txt")"
"$vrdeform" touch "$dir/moved.obj" --replay "$dir/moved.session" > "$dir/moved.txt" 2>&1
grep -q "replay: 270 steps, identical" "$dir/moved.txt" || fail "the new path: $(tail -3 "$dir/moved.txt")"
"$vrdeform" touch "$meshes/sphere_coarse.obj" --replay "$dir/moved.session" > "$dir/other.txt" 2>&1
[ $? -eq 2 ] && grep -q "the mesh differs from the one recorded" "$dir/other.txt" ||
  fail "another mesh: $(cat "$dir/other.txt")"
echo "PASS: touch = run of the same scene over $rows steps; a moved mesh replays from its new path"
