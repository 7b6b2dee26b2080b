#!/usr/bin/env bash
# `--scheme irregular` from the command line: the walk printed with its corner pointers, the
# screen BSP's figures in --stats, the same depth image as brute force, bad values refused.
set -u
LANCER="$1"; SRC="$2"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

out=$("$LANCER" trace builtin:default --scheme irregular --irregular-frame camera --pixel 40 30 --width 64 --height 64) \
  || fail "trace exited non-zero"
echo "$out" | grep -q "^  pointer [0-9]* -> [0-9]* (corner [0-9])" || fail "no corner pointer in the walk: $out"
echo "$out" | grep -q "^  region [0-9]*  t = \[" || fail "no region in the walk"
echo "$out" | grep -q "^hit t = " || fail "no hit"
"$LANCER" trace builtin:default --scheme irregular --irregular-frame camera --pixel 40 30 --width 64 --height 64 --json \
  | grep -q '"event": "pointer"' || fail "no pointer event in --json"

for h in first balanced fewest-cuts; do
  "$LANCER" render builtin:drilled:3 --scheme irregular --bsp-heuristic $h --width 48 --height 40 \
    --threads 2 -o "$tmp/i.png" --depth "$tmp/i_$h.pfm" --stats "$tmp/s.json" >/dev/null \
    || fail "render --bsp-heuristic $h"
  for k in zones cut_segments slabs regions build_ms memory_bytes pointer_steps; do
    grep -q "\"$k\"" "$tmp/s.json" || fail "--stats has no $k"
  done
  grep -q '"walk_errors": 0' "$tmp/s.json" || fail "walk errors with $h"
done
"$LANCER" render builtin:drilled:3 --scheme brute --width 48 --height 40 --threads 2 \
  -o "$tmp/b.png" --depth "$tmp/b.pfm" >/dev/null || fail "brute render"
for h in first balanced fewest-cuts; do
  cmp -s "$tmp/b.pfm" "$tmp/i_$h.pfm" || fail "depth image of $h differs from brute force"
done

# Projective zones (the default): a primary ray walks in depth without corner pointers, and both
# frames render the same depth image.
out=$("$LANCER" trace builtin:default --scheme irregular --pixel 40 30 --width 64 --height 64) \
  || fail "projective trace exited non-zero"
echo "$out" | grep -q "^  region [0-9]*  t = \[" || fail "no region in the projective walk"
echo "$out" | grep -q "^  pointer" && fail "a corner pointer in a projective primary walk: $out"
# Its events: where it starts, where it leaves each slab (its far depth plane), and why.
echo "$out" | grep -q "^  start at (.*) in region [0-9]*" || fail "no start in the projective walk"
echo "$out" | grep -q "^  exit at t = .* through face z" || fail "no exit in the projective walk"
echo "$out" | grep -q "^    why: .*left projective slab [0-9]* of zone [0-9]* (region [0-9]*) through its far depth plane" \
  || fail "no why line of a projective slab: $out"
for f in camera projective; do
  "$LANCER" render builtin:lattice:3 --scheme irregular --irregular-frame $f --width 48 --height 40 \
    --threads 2 -o "$tmp/f.png" --depth "$tmp/f_$f.pfm" --stats "$tmp/f.json" >/dev/null \
    || fail "render --irregular-frame $f"
  grep -q "\"frame\": *\"$f\"" "$tmp/f.json" || fail "--stats has no frame $f"
done
cmp -s "$tmp/f_camera.pfm" "$tmp/f_projective.pfm" || fail "camera and projective frames differ"
msg=$("$LANCER" render builtin:default --scheme irregular --irregular-frame nosuch -o "$tmp/x.png" 2>&1) \
  && fail "unknown frame accepted"
echo "$msg" | grep -q -- "--irregular-frame" || fail "message does not name the option: $msg"
msg=$("$LANCER" render builtin:default --scheme irregular --bsp-heuristic nosuch -o "$tmp/x.png" 2>&1) \
  && fail "unknown heuristic accepted"
echo "$msg" | grep -q -- "--bsp-heuristic" || fail "message does not name the option: $msg"
msg=$("$LANCER" render builtin:default --scheme irregular --max-objects -3 -o "$tmp/x.png" 2>&1) \
  && fail "negative --max-objects accepted"
echo "$msg" | grep -q -- "--max-objects" || fail "message does not name the option: $msg"
[ -e "$tmp/x.png" ] && fail "an image was written after an error"
echo ok
