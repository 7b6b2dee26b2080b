#!/usr/bin/env bash
# The subdivision knobs from the command line (docs/regular.md, "Explicit knobs"): at the
# defaults the cost stop decides; an explicit --max-level or --max-objects builds by the
# report's rule, so each changes the structure; `--stats` counts the leaves (zones) by the
# reason their cell was not split, and the counts add up to them. Usage: knobs_cli.sh LANCER SRC
set -u
LANCER="$1"; SRC="$2"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# stats NAME ARGS...: render builtin:default (unless ARGS name a scene) with ARGS into NAME.json.
stats() {
  local name=$1; shift
  "$LANCER" render "$@" --width 48 --height 32 --threads 2 -o "$tmp/$name.png" \
    --stats "$tmp/$name.json" -q 2>"$tmp/err" || fail "render $*: $(cat "$tmp/err")"
}
stats auto builtin:default
stats auto_mo4 builtin:default --max-objects auto
stats mo1 builtin:default --max-objects 1
stats l4 builtin:default --max-level 4 --max-objects 1
stats l8 builtin:default --max-level 8 --max-objects 1
stats l12 builtin:default --max-level 12 --max-objects 1
stats l8_auto builtin:default --max-level 8
stats i_auto builtin:default --scheme irregular
stats i_mo1 builtin:default --scheme irregular --max-objects 1
stats i_mo16 builtin:default --scheme irregular --max-objects 16
stats b_auto builtin:balls:2 --scheme irregular
stats b_mo1 builtin:balls:2 --scheme irregular --max-objects 1
stats b_mo2 builtin:balls:2 --scheme irregular --max-objects 2
# Over its memory budget the irregular screen BSP stops: those zones count as memory.
stats sponge_i "$SRC/assets/openscad/sponge.csg" --scheme irregular --memory-budget 256K
stats sponge_r "$SRC/assets/openscad/sponge.csg" --scheme regular

python3 - "$tmp" <<'PY' || fail "--stats contents"
import json, os, sys
d = sys.argv[1]
def j(name):
    return json.load(open(os.path.join(d, name + ".json")))
keys = {"max_objects", "max_level", "cost", "memory"}
for name in sorted(f[:-5] for f in os.listdir(d) if f.endswith(".json")):
    s = j(name)
    r = s["stop_reasons"]
    assert set(r) == keys, (name, r)
    count = s["zones"] if s["scheme"] == "irregular" else s["leaves"]
    assert sum(r.values()) == count, (name, r, count)
    if s["scheme"] == "regular":
        assert count == s["regions"], (name, count, s["regions"])
# The defaults: the cost stop decides, as `--max-objects auto`; on builtin:default it splits
# down to max-objects (6 leaves), the splits paying once a primitive crossing both halves of a
# cell counts once (docs/regular.md, "Cost-driven splits").
a = j("auto")
assert a["cost_stop"] is True and a["regions"] == 6 and a["max_objects"] == 4, a["regions"]
assert a["stop_reasons"]["max_objects"] == 6, a["stop_reasons"]
assert j("auto_mo4")["regions"] == 6
# An explicit knob: the report's rule.
for name in ("mo1", "l4", "l8", "l12", "l8_auto", "i_mo1", "b_mo1"):
    assert j(name)["cost_stop"] is False, name
r = [j(n)["regions"] for n in ("l4", "l8", "l12")]
assert r[0] < r[1] < r[2], r
assert j("mo1")["regions"] > a["regions"], j("mo1")["regions"]
# max-level 8 with max-objects 4 stops where the defaults do (every leaf at 4 primitives or
# fewer); with max-objects 1 the level decides.
assert j("l8_auto")["regions"] == a["regions"], j("l8_auto")["regions"]
assert j("l8")["regions"] > j("l8_auto")["regions"], j("l8")["regions"]
# max-level and max-objects stops are counted as such.
assert j("l4")["stop_reasons"]["max_level"] > 0 and j("l4")["stop_reasons"]["max_objects"] > 0
# The irregular scheme's max-objects is alive below the cost stop's choice too.
assert j("i_mo1")["zones"] > j("i_auto")["zones"] > j("i_mo16")["zones"], \
    [j(n)["zones"] for n in ("i_mo1", "i_auto", "i_mo16")]
assert j("b_mo1")["zones"] != j("b_mo2")["zones"], j("b_mo1")["zones"]
assert j("b_mo1")["zones"] > j("b_auto")["zones"], (j("b_mo1")["zones"], j("b_auto")["zones"])
assert j("i_mo1")["stop_reasons"]["max_objects"] > 0
assert j("sponge_i")["stop_reasons"]["memory"] > 0, j("sponge_i")["stop_reasons"]
assert j("sponge_i")["bsp_stopped"] is True
PY

# max-objects takes a number or auto; anything else is refused naming the option.
out=$("$LANCER" render builtin:default --max-objects many -o "$tmp/x.png" 2>&1); rc=$?
[ $rc -eq 2 ] || fail "--max-objects many: status $rc"
echo "$out" | grep -q -- "--max-objects" || fail "--max-objects many: not named: $out"
echo "$out" | grep -q "auto" || fail "--max-objects many: auto not offered: $out"
out=$("$LANCER" render builtin:default --max-objects 0 -o "$tmp/x.png" 2>&1); rc=$?
[ $rc -eq 2 ] || fail "regular --max-objects 0: status $rc"
echo "$out" | grep -q -- "--max-objects 0" || fail "regular --max-objects 0: not named: $out"
echo ok
