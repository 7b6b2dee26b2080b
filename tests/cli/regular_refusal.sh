#!/usr/bin/env bash
# `--scheme regular` from the command line: absurd max-level / max-objects are refused with a
# message naming the options (never attempted); a sane build reports its figures in --stats and
# `lancer trace` prints its walk.
set -u
LANCER="$1"; SRC="$2"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

out=$("$LANCER" render builtin:lattice --scheme regular --max-level 30 --max-objects 2 --no-cost-stop \
      --width 8 --height 8 -o "$tmp/x.png" 2>&1) && fail "absurd parameters accepted"
echo "$out" | grep -q -- "--max-level 30 --max-objects 2" || fail "message does not name the options: $out"
echo "$out" | grep -q "memory budget" || fail "message does not say why: $out"
[ -e "$tmp/x.png" ] && fail "an image was written for a refused build"

# A full table at level 30 (4 GiB) is refused under a 1 GiB budget, naming both options; the
# same level with sub-tables is built.
out=$("$LANCER" render "$SRC/assets/spd/balls4.nff" --scheme regular --full-table --max-level 30 --max-objects 4 \
      --memory-budget 1G --width 8 --height 8 -o "$tmp/y.png" 2>&1) && fail "a 4 GiB full table accepted"
echo "$out" | grep -q -- "--full-table" || fail "message does not name the option: $out"
echo "$out" | grep -q -- "--memory-budget" || fail "message does not name the budget: $out"
out=$("$LANCER" render builtin:default --memory-budget lots -o "$tmp/w.png" 2>&1) && fail "a bad budget accepted"
echo "$out" | grep -q -- "--memory-budget" || fail "message does not name the option: $out"
"$LANCER" render "$SRC/assets/spd/balls4.nff" --scheme regular --max-level 30 --max-objects 4 \
    --width 8 --height 8 -o "$tmp/y.png" >/dev/null 2>"$tmp/log" || { cat "$tmp/log"; fail "sub-tables at level 30 refused"; }

# The automatic mode keeps within the builder's node limit: OpenSCAD's example020 (a twisted
# spring of 25,971 polytopes) would pass it at the automatic depth, and is built shallower
# ("auto_level_drop" in --stats) with the image of brute force; the same depth given
# explicitly is refused, naming the options.
"$LANCER" render "$SRC/assets/openscad/screws.csg" --width 48 --height 48 -o "$tmp/s.png" \
    --stats "$tmp/s.json" >/dev/null 2>"$tmp/log" || { cat "$tmp/log"; fail "example020 refused at the defaults"; }
grep -q '"auto_level_drop": [1-9]' "$tmp/s.json" || fail "example020 built at the full automatic depth?"
# Its twisted extrusions' slices stray from the exact surface by the bound the reader states.
grep -Eq '"model_error": [0-9.e-]*[1-9]' "$tmp/s.json" || fail "example020: no twist bound in --stats"
"$LANCER" render "$SRC/assets/openscad/screws.csg" --scheme brute --width 48 --height 48 -o "$tmp/sb.png" -q
cmp -s "$tmp/s.png" "$tmp/sb.png" || fail "example020: the regular image differs from brute force's"
out=$("$LANCER" render "$SRC/assets/openscad/screws.csg" --max-level 30 --max-objects 4 --width 8 --height 8 \
      -o "$tmp/e.png" 2>&1) && fail "example020 at an explicit --max-level 30 --max-objects 4 accepted"
echo "$out" | grep -q -- "--max-level 30 --max-objects 4: the regular subdivision would need more than" \
  || fail "message does not name the options: $out"

"$LANCER" render builtin:default --scheme regular --width 32 --height 32 --threads 2 \
    -o "$tmp/z.png" --stats "$tmp/s.json" >/dev/null 2>"$tmp/log" || { cat "$tmp/log"; fail "render failed"; }
for key in '"scheme": "regular"' '"full_table_bytes"' '"directory": "sub-tables"' '"leaves"' '"depth_xyz"' '"memory_bytes"'; do
  grep -q "$key" "$tmp/s.json" || fail "stats lack $key"
done
grep -q '"walk_errors": 0' "$tmp/s.json" || fail "walk errors in a default render"
grep -Eq '"model_error": 0(\.0)?[,}]' "$tmp/s.json" || fail "builtin:default is exact: model_error must be 0"

"$LANCER" trace builtin:default --scheme regular --width 64 --height 64 --pixel 32 32 >"$tmp/t.txt" 2>&1 \
  || { cat "$tmp/t.txt"; fail "trace failed"; }
grep -q "^  region [0-9]*  t = \[" "$tmp/t.txt" || fail "trace prints no region"
grep -q "^hit t = " "$tmp/t.txt" || fail "trace finds no hit"
echo ok
