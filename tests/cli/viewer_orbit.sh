#!/usr/bin/env bash
# `lancer view --orbit` (the frame-time benchmark's turn, scripts/frame-times): the camera turns
# DEG degrees about its target in each of the first --frames frames once the structure is
# ready, and --log-timings ends with the frames' times, the turning ones apart. Four turns of
# 90 degrees come back to the scene's own view (the viewport equals `lancer render`); two do not.
# Usage: viewer_orbit.sh LANCER SOURCE_DIR
set -euo pipefail
lancer=$1
xvfb_run="$(dirname "$0")/xvfb_run"  # xvfb-run -a (it says when xvfb is missing)
src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
viewport() { sed -n 's/.*image \([0-9]*\)x\([0-9]*\) at \([0-9]*\),\([0-9]*\)$/\3 \4/p' "$1"; }
view() {  # FRAMES NAME: turn 90 degrees in each of FRAMES frames, screenshot NAME.png
  timeout 240 "$xvfb_run" -s "-screen 0 1920x1080x24" "$lancer" view builtin:default \
    --frames "$1" --orbit 90 --log-timings --screenshot "$tmp/$2.png" \
    --width 480 --height 360 --ini none >"$tmp/$2.txt" 2>"$tmp/$2.err"
}
"$lancer" render builtin:default -o "$tmp/cpu.png" --width 480 --height 360 -q
view 4 full
python3 "$src/tests/support/png_compare.py" "$tmp/full.png" "$tmp/cpu.png" $(viewport "$tmp/full.txt") 20 60 240 300
# The summary: exactly the four turning frames, then the still ones until the image completed.
ms="p50 [0-9.]+ ms, p95 [0-9.]+ ms, max [0-9.]+ ms"
grep -Eq "^timing: frames since the structure was ready: turning: 4 frames, $ms, [0-9]+ over 33 ms, CPU $ms; still: [1-9][0-9]* frames, $ms" \
  "$tmp/full.err" || { cat "$tmp/full.err" >&2; exit 1; }
view 2 half
if python3 "$src/tests/support/png_compare.py" "$tmp/half.png" "$tmp/cpu.png" $(viewport "$tmp/half.txt") 20 60 240 300 2>/dev/null; then
  echo "two turns of 90 degrees left the view as it was" >&2
  exit 1
fi
# --orbit needs --frames, and a turn is at most half a circle.
if "$lancer" view builtin:default --orbit 10 --ini none 2>"$tmp/err.txt"; then
  echo "--orbit without --frames was accepted" >&2
  exit 1
fi
grep -q -- "--orbit" "$tmp/err.txt" || { cat "$tmp/err.txt" >&2; exit 1; }
if "$lancer" view builtin:default --frames 2 --orbit 400 --ini none 2>"$tmp/err.txt"; then
  echo "--orbit 400 was accepted" >&2
  exit 1
fi
grep -q -- "--orbit" "$tmp/err.txt" || { cat "$tmp/err.txt" >&2; exit 1; }
