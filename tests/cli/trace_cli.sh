#!/usr/bin/env bash
# `lancer trace` as a user runs it: the pixel's whole ray tree, at render's size and camera, with
# counts that are render's. Summed over every pixel of a small image, trace's counts are the
# render's `--stats` totals (tests, mailbox hits, regions, rays), for both schemes and bounces.
set -u
LANCER="$1"; SRC="$2"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# Default size: the scene's own, as render resolves it.
"$LANCER" render builtin:default -o "$tmp/d.png" --stats "$tmp/d.json" -q || fail "render"
size=$(python3 -c 'import json,sys; j=json.load(open(sys.argv[1])); print(j["width"], j["height"])' "$tmp/d.json")
"$LANCER" trace builtin:default --pixel 10 10 > "$tmp/t.txt" || fail "trace at the default size"
grep -q "^pixel (10, 10) of ${size/ /x}: " "$tmp/t.txt" || { cat "$tmp/t.txt"; fail "trace's size is not render's ($size)"; }

# The text form: the tree indented, each ray's line then its events (--no-cost-stop: the report's
# rule cuts the default scene into many leaves, where the cost rule keeps 2, so the walk has exits).
"$LANCER" trace builtin:default --width 64 --height 40 --pixel 10 30 --bounces 2 --no-cost-stop > "$tmp/t.txt" || fail "trace"
grep -q "^#0 primary from " "$tmp/t.txt" || fail "no primary ray line"
grep -q "^  #[0-9]* shadow of #0 to light 0" "$tmp/t.txt" || fail "no shadow ray under the primary"
grep -q "^  region [0-9]*  t = \[" "$tmp/t.txt" || fail "no region under the primary"
grep -q "^    test p[0-9]* " "$tmp/t.txt" || fail "no primitive test inside a region"
grep -q "^  exit at t = " "$tmp/t.txt" || fail "no exit"
grep -q "^    why: .* -> leaf [0-9]*" "$tmp/t.txt" || fail "no why line naming the next leaf"
grep -q "^    why: hit p[0-9]* .* inside this region" "$tmp/t.txt" || fail "no why line telling the hit"
grep -q "^hit t = " "$tmp/t.txt" || fail "no hit line"

# The JSON form: "rays", the primary first, each with its events.
"$LANCER" trace builtin:default --width 64 --height 40 --pixel 10 30 --bounces 2 --json > "$tmp/t.json" \
  || fail "trace --json"
python3 - "$tmp/t.json" <<'EOF' || fail "trace JSON"
import json, sys
j = json.load(open(sys.argv[1]))
rays = j["rays"]
assert rays[0]["kind"] == "primary" and rays[0]["parent"] == -1, rays[0]
assert j["events"] == rays[0]["events"]
kinds = {r["kind"] for r in rays}
assert "shadow" in kinds, kinds
for i, r in enumerate(rays):
    for key in ("kind", "parent", "origin", "direction", "tmin", "tmax", "events", "hit"):
        assert key in r, (i, key)
    if r["kind"] == "shadow":
        assert "light" in r and "occluded" in r, r
    if i:
        assert 0 <= r["parent"] < i, r
    assert r["events"][0]["event"] == "ray_begin" and r["events"][-1]["event"] == "ray_end"
regions = 0
for r in rays:
    for e in r["events"]:
        if e["event"] == "region":
            assert len(e["corners"]) == 8 and all(len(c) == 3 for c in e["corners"]), e
            assert isinstance(e["why"], str) and e["why"], e
            regions += 1
assert regions == j["region_visits"], (regions, j["region_visits"])
tests = sum(r["counters"]["prim_tests"] for r in rays)
assert tests == j["prim_tests"], (tests, j["prim_tests"])
# Each ray's wasted work: its tests, and the wasted ones' events tagged with their class.
for r in rays:
    w = r["wasted"]
    assert w["tests"] == r["counters"]["prim_tests"], (w, r["counters"])
    assert w["wasted"] == w["repeats"] + w["misses"] + w["beyond_exit"] + w["no_effect"], w
    tagged = [e["wasted"] for e in r["events"] if "wasted" in e]
    assert len(tagged) == w["wasted"], (tagged, w)
    assert all(e["event"] == "prim_test" for e in r["events"] if "wasted" in e)
EOF
"$LANCER" trace builtin:default --width 64 --height 40 --pixel 10 30 \
  | grep -q "^wasted work of #0: [0-9]* tests\?, [0-9]* wasted" || fail "trace text lacks the wasted work"

# Summed over every pixel, trace's counts are render's totals.
w=6; h=4
for args in "builtin:default --scheme regular --bounces 0" \
            "builtin:default --scheme irregular --bounces 2" \
            "builtin:balls:1 --scheme regular --step push --bounces 2" \
            "builtin:balls:1 --scheme irregular --irregular-frame camera --bounces 2"; do
  "$LANCER" render $args --width $w --height $h --threads 1 -o "$tmp/s.png" --stats "$tmp/s.json" -q \
    || fail "render $args"
  for ((y = 0; y < h; ++y)); do
    for ((x = 0; x < w; ++x)); do
      "$LANCER" trace $args --width $w --height $h --pixel $x $y --json > "$tmp/p_${x}_$y.json" \
        || fail "trace $args --pixel $x $y"
    done
  done
  python3 - "$tmp" "$w" "$h" <<'EOF' || fail "trace counts of $args differ from render's"
import json, sys
d, w, h = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
stats = json.load(open(d + "/s.json"))
total = {"prim_tests": 0, "mailbox_hits": 0, "region_visits": 0, "rays": 0}
for y in range(h):
    for x in range(w):
        c = json.load(open("%s/p_%d_%d.json" % (d, x, y)))["counters"]
        for k in total:
            total[k] += c[k]
for k in total:
    assert total[k] == stats[k], (k, total[k], stats[k])
EOF
done

# A pixel outside the image is refused, naming the option.
out=$("$LANCER" trace builtin:default --width 64 --height 40 --pixel 64 0 2>&1) && fail "pixel outside accepted"
echo "$out" | grep -q "^error: --pixel 64 0 is outside the 64x40 image" || fail "bad message: $out"
echo "ok"
