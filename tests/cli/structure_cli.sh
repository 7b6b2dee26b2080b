#!/usr/bin/env bash
# `lancer structure`: the dump of docs/design.md section 6 for each scheme and both cameras, read back
# and checked (keys, counts, zones tiling the image, slabs in depth order); bad options and
# unwritable outputs refused with exit status 2, naming the option, leaving no file.
set -u
LANCER="$1"; SRC="$2"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

"$LANCER" structure builtin:default --scheme regular --width 64 --height 48 -o "$tmp/r.json" -q \
  || fail "regular dump exited non-zero"
"$LANCER" structure builtin:default --scheme brute --width 64 --height 48 -o "$tmp/b.json" -q \
  || fail "brute dump exited non-zero"
"$LANCER" structure builtin:default --scheme irregular --width 64 --height 48 -o "$tmp/i.json" -q \
  || fail "irregular dump exited non-zero"
"$LANCER" structure "$SRC/assets/openscad/bracket.csg" --scheme irregular --irregular-frame camera \
  --width 64 --height 48 -o "$tmp/c.json" --all -q || fail "irregular --all dump exited non-zero"
# An orthographic camera: its camera frame maps to pixels.
cat > "$tmp/ortho.json" <<'JSON'
{"camera": {"from": [0, -10, 0.3], "at": [0, 0, 0.3], "up": [0, 0, 1], "projection": "orthographic",
            "ortho_height": 3, "width": 64, "height": 48},
 "scene": {"union": [{"sphere": {"center": [-0.6, 0, 0], "radius": 0.5}},
                     {"box": {"min": [0.2, -0.4, -0.4], "max": [1.0, 0.4, 0.9]}}]}}
JSON
ortho="$tmp/oi.json"
"$LANCER" structure "$tmp/ortho.json" --scheme irregular -o "$ortho" -q \
  || fail "orthographic irregular dump exited non-zero"

python3 - "$tmp" "$ortho" <<'PY' || fail "dump contents"
import json, sys
tmp, ortho = sys.argv[1], sys.argv[2]
def load(n):
    return json.load(open(n if n.startswith("/") else f"{tmp}/{n}"))
def box_ok(b):
    return len(b) == 2 and all(b[0][k] <= b[1][k] for k in range(3))
for name, scheme in (("r.json", "regular"), ("b.json", "brute"), ("i.json", "irregular")):
    j = load(name)
    assert j["scheme"] == scheme, name
    assert j["width"] == 64 and j["height"] == 48, name
    assert all(k in j["camera"] for k in ("from", "at", "up", "fov", "width", "height")), j["camera"]
    assert j["summary"] is False
    assert j["primitives"] and all({"id", "kind", "live", "box"} <= p.keys() for p in j["primitives"])
    assert all(box_ok(p["box"]) for p in j["primitives"] if p["live"])
r = load("r.json")["regular"]
assert len(r["directory"]) == 3 and box_ok(r["bounds"])
vol = lambda b: (b[1][0]-b[0][0]) * (b[1][1]-b[0][1]) * (b[1][2]-b[0][2])
assert abs(sum(vol(l["box"]) for l in r["leaves"]) - vol(r["bounds"])) < 1e-9 * vol(r["bounds"])
assert [l["id"] for l in r["leaves"]] == list(range(len(r["leaves"])))
assert load("r.json")["regions"] == len(r["leaves"])

def check_frame(f, frame, units, w=64, h=48):
    assert f["frame"] == frame and f["units"] == units, (f["frame"], f["units"])
    area = 0.0
    for z in f["zones"]:
        xs = [p[0] for p in z["polygon"]]; ys = [p[1] for p in z["polygon"]]
        area += (max(xs) - min(xs)) * (max(ys) - min(ys))
        if units == "pixels":
            assert min(xs) >= 0 and max(xs) <= w and min(ys) >= 0 and max(ys) <= h
        z1 = None
        for s in z["slabs"]:
            assert s["z0"] < s["z1"] and (z1 is None or s["z0"] == z1)
            z1 = s["z1"]
    (x0, y0), (x1, y1) = f["rect"]
    if units == "pixels":
        x0, y0, x1, y1 = max(x0, 0), max(y0, 0), min(x1, w), min(y1, h)
    want = max(0, x1 - x0) * max(0, y1 - y0)
    assert abs(area - want) < 1e-6 * want, (area, want)
    nodes = [b["node"] for b in f["bsp"]]
    assert nodes == list(range(len(nodes))) and len(nodes) == f["bsp_node_count"]
i = load("i.json")
check_frame(i["irregular"], "camera", "camera")
check_frame(i["projective"], "projective", "pixels")
c = load("c.json")
assert "projective" not in c
check_frame(c["irregular"], "camera", "camera")
o = load(ortho)
assert o["camera"]["projection"] == "orthographic"
assert "projective" not in o
check_frame(o["irregular"], "camera", "pixels")
PY

# balls4's regular structure (8728 leaves at the defaults) is dumped in full.
"$LANCER" structure "$SRC/assets/spd/balls4.nff" -o "$tmp/b4.json" -q || fail "balls4 dump"
python3 -c "import json,sys; j=json.load(open(sys.argv[1])); assert len(j['regular']['leaves']) == j['regions'] > 1000" "$tmp/b4.json" \
  || fail "balls4 dump contents"

# Errors: exit status 2, the option named, no file (nor temporary) left.
out=$("$LANCER" structure builtin:default 2>&1); [ $? -eq 2 ] || fail "missing -o: not exit 2"
echo "$out" | grep -q -- "--output" || fail "missing -o: message does not name it: $out"
out=$("$LANCER" structure builtin:default -o "$tmp/no/such/dir/x.json" 2>&1); [ $? -eq 2 ] || fail "unwritable -o: not exit 2"
echo "$out" | grep -q -- "-o " || fail "unwritable -o: message does not name the option: $out"
out=$("$LANCER" structure builtin:default --max-level x -o "$tmp/x.json" 2>&1); [ $? -eq 2 ] || fail "bad --max-level: not exit 2"
echo "$out" | grep -q -- "--max-level" || fail "bad --max-level: message does not name it: $out"
out=$("$LANCER" structure builtin:lattice --scheme regular --max-level 30 --max-objects 2 --no-cost-stop -o "$tmp/x.json" 2>&1) \
  && fail "absurd build accepted"
[ -e "$tmp/x.json" ] || [ -e "$tmp/x.json.tmp" ] && fail "a file was left by a failed dump"
out=$("$LANCER" structure "$tmp/missing.nff" -o "$tmp/x.json" 2>&1); [ $? -eq 2 ] || fail "missing scene: not exit 2"
[ -e "$tmp/x.json" ] && fail "a file was written for a missing scene"
# A nearly singular transform (scale 1e-300, issue 28 item 5) is handled: every scheme builds,
# and no NaN or infinity reaches the dumped structure (a zero scale is refused by the reader,
# tests/openscad_reader_test.cpp).
printf 'multmatrix([[1e-300,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]) cube(size=[1,1,1]);\nscale([1,1e-300,1]) sphere(r=1);\n' \
  > "$tmp/tiny.csg"
for s in brute regular irregular bvh; do
  "$LANCER" structure "$tmp/tiny.csg" --scheme "$s" --width 16 --height 16 -o "$tmp/tiny-$s.json" -q \
    || fail "tiny-scale dump ($s) exited non-zero"
  python3 - "$tmp/tiny-$s.json" <<'PY' || fail "tiny-scale dump ($s) holds NaN or infinity"
import json, sys
def bad(c):
    raise ValueError(c)
json.load(open(sys.argv[1]), parse_constant=bad)
PY
done
echo "ok"
