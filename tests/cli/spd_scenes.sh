#!/usr/bin/env bash
# Every SPD scene (NFF) and every OpenSCAD asset loads and renders with the brute-force scheme.
set -euo pipefail
LANCER="$1"; SRC="$2"
out=$(mktemp -d); trap 'rm -rf "$out"' EXIT
for f in "$SRC"/assets/spd/*.nff "$SRC"/assets/openscad/*.csg; do
  name=$(basename "$f")
  "$LANCER" render "$f" --scheme brute --width 40 --height 40 --bounces 0 --threads 2 -q \
    -o "$out/$name.png" --depth "$out/$name.pfm" || { echo "FAIL: $name did not render"; exit 1; }
  [ -s "$out/$name.png" ] && [ -s "$out/$name.pfm" ] || { echo "FAIL: $name wrote no image"; exit 1; }
done
# A .csg without a sidecar is framed from OpenSCAD's default view.
cp "$SRC/assets/openscad/bracket.csg" "$out/lonely.csg"
"$LANCER" render "$out/lonely.csg" --width 32 -q -o "$out/lonely.png"
[ -s "$out/lonely.png" ] || { echo "FAIL: no image for a .csg without sidecar"; exit 1; }
echo "PASS"
