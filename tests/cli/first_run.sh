#!/usr/bin/env bash
# What a new user tries first: image formats, the view's help, a screenshot without a display.
# Usage: first_run.sh LANCER SOURCE_DIR
set -u
LANCER="$1"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# -o a.jpg writes a JPEG (not a PNG under a .jpg name); an unknown extension is refused before
# the render, naming the file, and nothing is written.
"$LANCER" render builtin:default --width 64 --height 40 -o "$tmp/a.jpg" -q || fail "render -o a.jpg"
head -c 3 "$tmp/a.jpg" | od -An -tx1 | grep -q "ff d8 ff" || fail "a.jpg is not a JPEG"
"$LANCER" render builtin:default --width 64 --height 40 -o "$tmp/b.JPEG" -q || fail "render -o b.JPEG"
head -c 3 "$tmp/b.JPEG" | od -An -tx1 | grep -q "ff d8 ff" || fail "b.JPEG is not a JPEG"
out=$("$LANCER" render builtin:default --width 64 --height 40 -o "$tmp/c.bmp" 2>&1); status=$?
[ "$status" -eq 2 ] || fail "-o c.bmp: exit status $status, expected 2"
grep -q "error: .*c.bmp.*unknown image format" <<<"$out" || fail "-o c.bmp: $out"
[ ! -e "$tmp/c.bmp" ] || fail "c.bmp written"

# view --help names every scene format.
# From a file: with pipefail, `grep -q` quitting at its match could fail the writer (SIGPIPE).
"$LANCER" view --help > "$tmp/view-help.txt"
grep -q "\.csg" "$tmp/view-help.txt" || fail "view --help does not mention .csg"

# Without a display, --screenshot receives the headless render.
out=$(env -u DISPLAY -u WAYLAND_DISPLAY "$LANCER" view builtin:default --width 64 --height 40 \
      --frames 1 --screenshot "$tmp/shot.png" 2>&1) || fail "headless view: $out"
head -c 8 "$tmp/shot.png" | od -An -c | grep -q "P   N   G" || fail "no headless screenshot: $out"
echo "ok"
