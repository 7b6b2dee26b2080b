#!/usr/bin/env bash
# `lancer render` and `lancer trace` as a user runs them: outputs, errors, exit statuses.
set -u
LANCER="$1"; SRC="$2"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# A render writes the PNG, the depth PFM and the stats JSON.
"$LANCER" render builtin:default --width 64 --height 40 -o "$tmp/a.png" --depth "$tmp/a.pfm" --stats "$tmp/a.json" -q \
  || fail "render exited non-zero"
[ -s "$tmp/a.png" ] || fail "no PNG"
head -c 8 "$tmp/a.png" | od -An -c | grep -q "P   N   G" || fail "not a PNG"
head -c 11 "$tmp/a.pfm" | grep -q "^Pf" || fail "not a PFM"
for key in scheme width height threads build_ms render_ms rays primary_rays prim_tests mailbox_hits \
           region_visits regions memory_bytes max_level max_objects step; do
  grep -q "\"$key\"" "$tmp/a.json" || fail "stats lack $key"
done
grep -q '"primary_rays": 2560' "$tmp/a.json" || fail "primary_rays is not 64*40"

# The light buffer: on by default for the accelerated schemes, --no-light-buffer turns it off;
# the image is the same either way, and brute force never uses it.
"$LANCER" render "$SRC/assets/spd/balls1.nff" --width 48 --height 48 -o "$tmp/lb.png" --stats "$tmp/lb.json" -q \
  || fail "render balls1"
"$LANCER" render "$SRC/assets/spd/balls1.nff" --width 48 --height 48 -o "$tmp/nolb.png" --stats "$tmp/nolb.json" -q \
  --no-light-buffer || fail "render --no-light-buffer"
cmp -s "$tmp/lb.png" "$tmp/nolb.png" || fail "the light buffer changed the image"
grep -q '"light_buffer_skips": [1-9]' "$tmp/lb.json" || fail "the light buffer skipped no shadow ray"
grep -q '"light_buffer_skips": 0' "$tmp/nolb.json" || fail "--no-light-buffer still used it"
"$LANCER" render "$SRC/assets/spd/balls1.nff" --width 48 --height 48 -o "$tmp/bf.png" --stats "$tmp/bf.json" -q \
  --scheme brute || fail "render brute"
grep -q '"light_buffer_skips": 0' "$tmp/bf.json" || fail "brute force used the light buffer"
cmp -s "$tmp/lb.png" "$tmp/bf.png" || fail "regular with the light buffer differs from brute force"

# --width alone keeps the scene's aspect (640x400 -> 80x50).
"$LANCER" render builtin:default --width 80 -o "$tmp/b.png" --stats "$tmp/b.json" -q || fail "render --width"
grep -q '"height": 50' "$tmp/b.json" || fail "--width did not keep the aspect"

# Bad options: non-zero exit, the option named.
out=$("$LANCER" render builtin:default -o "$tmp/c.png" --scheme nonsense 2>&1); status=$?
[ "$status" -eq 2 ] || fail "bad --scheme: exit status $status, expected 2"
echo "$out" | grep -q -- "--scheme" || fail "bad --scheme not named: $out"
out=$("$LANCER" render builtin:default -o "$tmp/c.png" --width -3 2>&1) && fail "negative width accepted"
echo "$out" | grep -q -- "--width" || fail "bad --width not named: $out"
out=$("$LANCER" render builtin:default -o "$tmp/c.png" --max-level 100000 2>&1) && fail "huge max-level accepted"
echo "$out" | grep -q -- "--max-level" || fail "huge --max-level not named: $out"
[ ! -e "$tmp/c.png" ] || fail "an image was written despite the error"
out=$("$LANCER" render builtin:default -o "$tmp/c.png" --max-levle 3 2>&1); status=$?
[ "$status" -eq 2 ] || fail "misspelt option: exit status $status, expected 2"
echo "$out" | grep -q "^error: " || fail "misspelt option: no 'error:' prefix: $out"
echo "$out" | grep -q "did you mean --max-level?" || fail "misspelt option: no suggestion: $out"

# --camera: the sidecar's keys; a .csg's own sidecar given again changes nothing; errors name
# the file, line and column.
csg="$SRC/assets/openscad/bracket.csg"
"$LANCER" render "$csg" --width 40 -q -o "$tmp/own.png" --depth "$tmp/own.pfm" || fail "render .csg"
"$LANCER" render "$csg" --width 40 -q -o "$tmp/cam.png" --depth "$tmp/cam.pfm" \
  --camera "$SRC/assets/openscad/bracket.camera.json" || fail "render --camera"
cmp -s "$tmp/own.pfm" "$tmp/cam.pfm" || fail "--camera with the scene's own sidecar changed the image"
printf '{"from": [0, 0, 5],\n "at": [0, 0, 5]}\n' > "$tmp/bad.camera.json"
out=$("$LANCER" render builtin:default -o "$tmp/c.png" --camera "$tmp/bad.camera.json" 2>&1); status=$?
[ "$status" -eq 2 ] || fail "bad --camera: exit status $status, expected 2"
echo "$out" | grep -q "^error: .*bad.camera.json:1:1: " || fail "bad --camera message: $out"
out=$("$LANCER" trace builtin:default --pixel 1 1 --camera "$tmp/none.json" 2>&1) && fail "missing --camera accepted"
echo "$out" | grep -q "none.json" || fail "missing --camera not named: $out"

# A bad scene file: file:line:col, non-zero exit, no output written.
printf '{\n  "scene": {"sphere": {"radius": -2}}\n}\n' > "$tmp/bad.json"
out=$("$LANCER" render "$tmp/bad.json" -o "$tmp/d.png" 2>&1); status=$?
[ "$status" -eq 2 ] || fail "bad scene: exit status $status, expected 2"
echo "$out" | grep -q "bad.json:2:24: expected a positive number" || fail "bad scene message: $out"
[ ! -e "$tmp/d.png" ] || fail "an image was written for a bad scene"
out=$("$LANCER" render "$tmp/missing.json" -o "$tmp/d.png" 2>&1) && fail "missing scene accepted"
echo "$out" | grep -q "missing.json: no such file" || fail "missing file message: $out"
out=$("$LANCER" render builtin:nosuch -o "$tmp/d.png" 2>&1) && fail "unknown builtin accepted"
echo "$out" | grep -q "unknown built-in scene" || fail "unknown builtin message: $out"

# An unwritable output: an error, and no partial file left behind.
out=$("$LANCER" render builtin:default --width 16 -o "$tmp/no/such/dir/e.png" 2>&1) && fail "unwritable output accepted"
echo "$out" | grep -q "e.png" || fail "unwritable output message: $out"

# trace: the walk and the hit, as text and JSON.
"$LANCER" trace builtin:default --width 64 --height 40 --pixel 32 20 > "$tmp/t.txt" || fail "trace"
grep -q "hit t = " "$tmp/t.txt" || fail "trace shows no hit"
"$LANCER" trace builtin:default --width 64 --height 40 --pixel 32 20 --json > "$tmp/t.json" || fail "trace --json"
grep -q '"prim_test"' "$tmp/t.json" || fail "trace --json lacks events"
out=$("$LANCER" trace builtin:default --width 64 --height 40 --pixel 64 0 2>&1) && fail "pixel outside accepted"
echo "$out" | grep -q -- "--pixel" || fail "outside pixel message: $out"

# --help lists every common option.
# --facets openscad: a sphere becomes OpenSCAD's polyhedron, its sagitta in model_error; exact
# by default; a value that is not one is refused naming the option.
echo 'sphere(r = 10, $fn = 0, $fa = 12, $fs = 2);' > "$tmp/ball.csg"
"$LANCER" render "$tmp/ball.csg" -o "$tmp/f.png" --width 16 --height 16 --facets openscad \
  --stats "$tmp/f.json" -q || fail "--facets openscad"
"$LANCER" render "$tmp/ball.csg" -o "$tmp/e.png" --width 16 --height 16 --stats "$tmp/e.json" -q \
  || fail "exact sphere"
python3 - "$tmp/f.json" "$tmp/e.json" <<'PY' || fail "--facets stats"
import json, sys
f, e = (json.load(open(p)) for p in sys.argv[1:])
assert f["primitives"] == 14 and 0.1 < f["model_error"] < 0.2, f
assert e["primitives"] == 1 and e["model_error"] == 0, e
PY
out=$("$LANCER" render "$tmp/ball.csg" -o "$tmp/x.png" --facets round 2>&1) && fail "--facets round accepted"
echo "$out" | grep -q -- "--facets" || fail "--facets error does not name the option: $out"
help=$("$LANCER" render --help)
for opt in --width --height --scheme --max-level --max-objects --step --delta --threads --bounces --stats --depth; do
  echo "$help" | grep -q -- "$opt" || fail "render --help lacks $opt"
done
echo "ok"
