#!/usr/bin/env bash
# `--memory-budget` from the command line at the defaults, on the sponge-like model (221 cubes
# under one difference): under a tiny budget the regular scheme is refused with a message naming
# the budget and exit status 2, writing nothing (an image already there is left as it was); the
# irregular scheme stops subdividing within the budget (its light buffer left out) and renders
# brute force's depth image.
set -u
LANCER="$1"; SRC="$2"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
sponge="$SRC/assets/openscad/sponge.csg"

# Refused: nothing written, status 2, the limit named with the options that would lift it.
"$LANCER" render "$sponge" --scheme regular --memory-budget 256K --width 40 --height 40 \
  -o "$tmp/r.png" --stats "$tmp/r.json" --depth "$tmp/r.pfm" >"$tmp/out" 2>"$tmp/err"
status=$?
[ $status -eq 2 ] || fail "a regular build over a 256 KiB budget exited $status: $(cat "$tmp/err")"
grep -q "^error: --memory-budget 256.0 KiB: the regular subdivision .* passes its memory budget" "$tmp/err" \
  || fail "message does not name the budget: $(cat "$tmp/err")"
grep -q -- "raise --memory-budget" "$tmp/err" || fail "message does not say what lifts it: $(cat "$tmp/err")"
[ -s "$tmp/out" ] && fail "a refused build printed on stdout: $(cat "$tmp/out")"
left=$(ls -A "$tmp" | grep -v '^out$\|^err$')
[ -z "$left" ] || fail "a refused build left files: $left"
# An image already at the output path survives the refusal unchanged.
printf 'not an image' >"$tmp/keep.png"
"$LANCER" render "$sponge" --scheme regular --memory-budget 256K --width 40 --height 40 \
  -o "$tmp/keep.png" >/dev/null 2>&1 && fail "refused build exited 0"
[ "$(cat "$tmp/keep.png")" = "not an image" ] || fail "a refused build overwrote the output"

# Stopped: the same budget, the irregular scheme (both frames) within it, brute force's depths.
"$LANCER" render "$sponge" --scheme brute --width 40 --height 40 --threads 2 -o "$tmp/b.png" \
  --depth "$tmp/b.pfm" >/dev/null 2>"$tmp/err" || fail "brute render: $(cat "$tmp/err")"
for f in camera projective; do
  "$LANCER" render "$sponge" --scheme irregular --irregular-frame $f --memory-budget 256K \
    --width 40 --height 40 --threads 2 -o "$tmp/i.png" --depth "$tmp/i_$f.pfm" \
    --stats "$tmp/i.json" >/dev/null 2>"$tmp/err" || fail "irregular under 256 KiB ($f): $(cat "$tmp/err")"
  cmp -s "$tmp/b.pfm" "$tmp/i_$f.pfm" || fail "the stopped irregular build ($f) differs from brute force"
  python3 - "$tmp/i.json" <<'PY' || fail "--stats of the stopped irregular build ($f)"
import json, sys
j = json.load(open(sys.argv[1]))
def find(d, key):
    if isinstance(d, dict):
        if key in d:
            return d[key]
        for v in d.values():
            r = find(v, key)
            if r is not None:
                return r
    return None
assert find(j, "memory_budget") == 256 * 1024, j
assert find(j, "bsp_stopped") is True, "the budget did not stop the screen BSP"
# The whole structure within the budget: its light buffer (1.6 MiB) is left out, said so.
assert 0 < find(j, "memory_bytes") <= 256 * 1024, j["memory_bytes"]
assert find(j, "light_buffer_bytes") is None, j["light_buffer_bytes"]
assert "over a quarter of the memory budget" in find(j, "light_buffer_left_out"), j
PY
done
echo ok
