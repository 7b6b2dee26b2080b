#!/usr/bin/env bash
# `lancer bench --quick`: the report's CSV has the reference, the sweeps and the progressive
# passes, and the final pass equals the reference.
set -u
LANCER="$1"; SRC="$2"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
"$LANCER" bench --quick --scenes builtin:default --width 40 --height 24 --threads 2 --out "$tmp/b" 2>"$tmp/log" \
  || { cat "$tmp/log"; fail "bench exited non-zero"; }
csv="$tmp/b/report.csv"
head -1 "$csv" | grep -q "^scene,scheme,knob,value,build_ms,memory_bytes,regions,render_ms,speedup" || fail "CSV header"
grep -q "^builtin:default,brute,scheme,brute," "$csv" || fail "no brute-force reference row"
[ "$(grep -c ',progressive pass,' "$csv")" -eq 3 ] || fail "expected 3 progressive passes (16, 4, 1)"
# The last pass is the full image: no pixel differs from the reference.
grep ',progressive pass,1,' "$csv" | awk -F, '{ if ($15 != 0 || $16 != 0) exit 1 }' || fail "final pass differs from brute force"
# Every scheme row that was measured agrees with brute force at default settings.
awk -F, '$3=="scheme" && $15 != 0 { exit 1 }' "$csv" || fail "a scheme differs from brute force at defaults"
[ -s "$tmp/b/speed_vs_error-default.png" ] || fail "no speed_vs_error plot"
# The comparison table on a union-only scene: with the peer (Embree, when built in) come the
# schemes at --bounces 0, each compared with brute force at --bounces 0 after it was rendered.
"$LANCER" bench --schemes-only --no-plots --scenes builtin:balls:1 --width 48 --height 32 \
  --threads 2 --out "$tmp/s" 2>"$tmp/log" || { cat "$tmp/log"; fail "bench --schemes-only exited non-zero"; }
csv="$tmp/s/report.csv"
awk -F, '$3=="scheme" && $15 != 0 { exit 1 }' "$csv" || fail "--schemes-only: a scheme differs from brute force"
if grep -q ',embree,peer (bounces 0),' "$csv"; then
  [ "$(grep -c -E ',(regular|irregular),peer \(bounces 0\),' "$csv")" -eq 2 ] || fail "no scheme rows at --bounces 0"
  awk -F, '$3=="peer (bounces 0)" && $2!="embree" && $15 != 0 { exit 1 }' "$csv" \
    || fail "a scheme at --bounces 0 differs from brute force at --bounces 0"
fi
# A twisted extrusion's parts per slice as a knob: rows at 1 and 4 parts, the stated bound in
# the model_error column about 4 times smaller at 4 parts (--facets reaches the bench too).
"$LANCER" bench --quick --no-plots --no-mesh --schemes brute regular --facets openscad \
  --scenes "$SRC/assets/openscad/twists.csg" --width 24 --height 16 --threads 2 --repeats 1 \
  --out "$tmp/t" 2>"$tmp/log" || { cat "$tmp/log"; fail "bench of a twist exited non-zero"; }
python3 - "$tmp/t/report.csv" <<'PY' || fail "twist parts rows"
import csv, sys
rows = [r for r in csv.DictReader(open(sys.argv[1])) if r["knob"] == "twist parts"]
assert [r["value"] for r in rows] == ["1", "4"], rows
e = [float(r["model_error"]) for r in rows]
assert e[0] > 3.5 * e[1] > 0, e
assert all(r["depth_p99"] != "" for r in rows), rows
PY
out=$("$LANCER" bench --quick --scenes builtin:nosuch --out "$tmp/c" 2>&1) && fail "unknown scene accepted"
echo "$out" | grep -q "unknown built-in scene" || fail "bench error message: $out"
echo ok
