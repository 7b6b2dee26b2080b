#!/usr/bin/env bash
# scripts/scale-check on one small scene: each scheme is measured in a child process (peak
# memory, time), its hits equal brute force's on every pixel, the table and JSON are written; a
# limit broken is listed as a failure with exit status 1, a child killed with the step it was in;
# a bad limit is refused naming it.
set -u
LANCER="$1"; SRC="$2"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
export LANCER
"$SRC/scripts/scale-check" "$tmp/ok" --scenes builtin:balls:1 >"$tmp/out" 2>"$tmp/err" \
  || { cat "$tmp/out" "$tmp/err"; fail "scale-check exited non-zero on balls:1"; }
grep -q "^| builtin:balls:1 | 11 | regular |" "$tmp/out" || fail "no regular row: $(cat "$tmp/out")"
grep -q "^No failures" "$tmp/ok/scale.md" || fail "scale.md reports failures"
python3 - "$tmp/ok/scale.json" <<'PY' || fail "scale.json contents"
import json, sys
j = json.load(open(sys.argv[1]))
rows = {r["scheme"]: r for r in j["rows"]}
assert set(rows) == {"brute", "regular", "irregular", "bvh"}, rows.keys()  # --no-peer: no Embree
b = rows["brute"]
assert b["stride"] == 1 and b["primitives"] == 11
for s in ("regular", "irregular", "bvh"):
    r = rows[s]
    # Every pixel compared with brute force, none differing; the figures of a measured run.
    assert r["pixels_compared"] == b["width"] * b["height"] and r["hits_differing"] == 0, r
    assert r["peak_rss_bytes"] > r["structure_bytes"] > 0 and r["rays"] > 0, r
    assert 0 < r["total_s"] <= j["time_limit_s"], r
assert j["failures"] == []
PY
# A memory limit no process keeps to: every scheme is listed, with its peak, and exit status 1.
"$SRC/scripts/scale-check" "$tmp/low" --scenes builtin:balls:1 --memory-limit 1M >"$tmp/out" 2>&1
[ $? -eq 1 ] || fail "a broken limit did not exit 1"
grep -q "^- builtin:balls:1 regular: peak resident memory" "$tmp/out" || fail "regular not listed: $(cat "$tmp/out")"
grep -q "^- builtin:balls:1 irregular: peak resident memory" "$tmp/out" || fail "irregular not listed"
grep -q "^- builtin:balls:1 bvh: peak resident memory" "$tmp/out" || fail "bvh not listed"
# A child past --kill-after is killed and listed with the step it was in (balls:6, 597,871
# spheres, takes longer than 0.1 s to load anywhere; balls:5 came to load in 0.1 s), its CPU
# time and peak; the JSON row names the step.
"$LANCER" bench --scale --scenes builtin:balls:6 --schemes regular --no-peer --kill-after 0.1 \
  --out "$tmp/kill" >"$tmp/out" 2>&1
[ $? -eq 1 ] || fail "a killed child did not exit 1: $(cat "$tmp/out")"
grep -q "^- builtin:balls:6 regular: killed after 0.1 s while loading (CPU time .* s, peak RSS " \
  "$tmp/out" || fail "kill not listed with its step: $(cat "$tmp/out")"
python3 - "$tmp/kill/scale.json" <<'PY2' || fail "scale.json of the kill"
import json, sys
rows = json.load(open(sys.argv[1]))["rows"]
assert len(rows) == 1 and rows[0]["killed_while"] == "loading", rows
assert "primitives" not in rows[0] and rows[0]["failure"].startswith("killed after 0.1 s"), rows
PY2
# A build over --memory-budget is a refusal row naming the budget, a failure (exit status 1);
# the stopped irregular build under the same budget passes.
"$LANCER" bench --scale --scenes "$SRC/assets/openscad/sponge.csg" --schemes brute regular irregular \
  --width 24 --height 24 --no-peer --memory-budget 256K --out "$tmp/budget" >"$tmp/out" 2>&1
[ $? -eq 1 ] || fail "a refused build did not exit 1: $(cat "$tmp/out")"
grep -q "^- .*/sponge.csg regular: refused: --memory-budget 256.0 KiB: " "$tmp/budget/scale.md" \
  || fail "refusal not listed with its budget: $(cat "$tmp/out")"
grep -q "^- .*/sponge.csg irregular" "$tmp/budget/scale.md" \
  && fail "the stopped irregular build failed: $(cat "$tmp/out")"
python3 - "$tmp/budget/scale.json" <<'PY3' || fail "scale.json of the refusal"
import json, sys
rows = {r["scheme"]: r for r in json.load(open(sys.argv[1]))["rows"]}
assert rows["regular"]["refused"].startswith("--memory-budget 256.0 KiB"), rows["regular"]
i = rows["irregular"]
assert "failure" not in i and i["hits_differing"] == 0 and i["pixels_compared"] == 24 * 24, i
PY3
out=$("$LANCER" bench --scale --scenes builtin:balls:1 --kill-after -1 --out "$tmp/bad" 2>&1)
[ $? -eq 2 ] && echo "$out" | grep -q "^error: --kill-after" || fail "bad --kill-after: $out"
out=$("$LANCER" bench --scale --scenes builtin:balls:1 --memory-limit lots --out "$tmp/bad" 2>&1)
[ $? -eq 2 ] || fail "a bad --memory-limit was accepted"
echo "$out" | grep -q "^error: --memory-limit lots" || fail "message: $out"
out=$("$LANCER" bench --scale --scenes builtin:nosuch --out "$tmp/bad" 2>&1)
[ $? -eq 2 ] && echo "$out" | grep -q "builtin:nosuch: unknown built-in scene" || fail "unknown scene: $out"
echo ok
