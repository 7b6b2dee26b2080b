#!/usr/bin/env bash
# The viewer in a virtual X server: run 30 frames, wait for the render, save the window, and
# check the screenshot is the rendered scene (equal to `lancer render` between the panels) plus
# the UI, not a blank window. Usage: viewer_xvfb.sh LANCER SOURCE_DIR
set -euo pipefail
lancer=$1
xvfb_run="$(dirname "$0")/xvfb_run"  # xvfb-run -a (it says when xvfb is missing)
src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
# --width and --height are the image viewport's size (the window opens around it with the
# panels), with the scene's own camera: the viewport equals `lancer render` at that size.
# `lancer view` prints where the viewport lies ("image 900x560 at X,Y").
viewport() { sed -n 's/.*image \([0-9]*\)x\([0-9]*\) at \([0-9]*\),\([0-9]*\)$/\3 \4/p' "$1"; }
timeout 240 "$xvfb_run" -s "-screen 0 1920x1080x24" \
  "$lancer" view builtin:default --frames 30 --screenshot "$tmp/out.png" --width 900 --height 560 \
  --ini none >"$tmp/out.txt"
test -s "$tmp/out.png"
grep -q "image 900x560 at " "$tmp/out.txt" || { cat "$tmp/out.txt" >&2; exit 1; }
"$lancer" render builtin:default -o "$tmp/cpu.png" --width 900 --height 560 -q
# The Parameters panel: the left column, left of the viewport.
python3 "$src/tests/support/png_compare.py" "$tmp/out.png" "$tmp/cpu.png" $(viewport "$tmp/out.txt") 20 60 240 400
# Redrawing every frame (--continuous) the viewer still completes the image, and --log-timings
# reports each pass's latency and the UI's frame rate.
timeout 240 "$xvfb_run" -s "-screen 0 1280x1024x24" \
  "$lancer" view builtin:default --frames 150 --continuous --log-timings --width 320 --height 200 \
  --ini none 2>"$tmp/timings.txt"
grep -q "pass stride 16 visible" "$tmp/timings.txt" || { cat "$tmp/timings.txt" >&2; exit 1; }
grep -q "full image" "$tmp/timings.txt" || { cat "$tmp/timings.txt" >&2; exit 1; }
grep -q "timing: ui .* fps" "$tmp/timings.txt" || { cat "$tmp/timings.txt" >&2; exit 1; }
# A scripted run on a scene that cannot be loaded fails with the file's error, without hanging.
status=0
timeout 120 "$xvfb_run" "$lancer" view "$tmp/missing.nff" --frames 2 --ini none 2>"$tmp/err.txt" || status=$?
if [ "$status" != 2 ]; then
  echo "a missing scene must end with status 2, got $status" >&2
  exit 1
fi
grep -q "missing.nff" "$tmp/err.txt"
# A file dropped on the window opens: the window's own drop callback is handed the path after
# the first image (--drop), and the screenshot is then the dropped scene as `lancer render`
# draws it, with its path in the file field.
timeout 240 "$xvfb_run" -s "-screen 0 1920x1080x24" \
  "$lancer" view builtin:default --frames 5 --drop "$src/assets/spd/gears2.nff" \
  --screenshot "$tmp/dropped.png" --width 900 --height 560 --ini none >"$tmp/dropped.txt"
"$lancer" render "$src/assets/spd/gears2.nff" -o "$tmp/gears.png" --width 900 --height 560 -q
python3 "$src/tests/support/png_compare.py" "$tmp/dropped.png" "$tmp/gears.png" $(viewport "$tmp/dropped.txt") 20 60 240 400
# A dropped file that does not load keeps the previous scene on screen and says why.
printf 'v\nfrom 0 0 0\nbogus line\n' >"$tmp/broken.nff"
timeout 240 "$xvfb_run" -s "-screen 0 1920x1080x24" \
  "$lancer" view builtin:default --frames 5 --drop "$tmp/broken.nff" \
  --screenshot "$tmp/kept.png" --width 900 --height 560 --ini none 2>"$tmp/drop-err.txt" \
  >"$tmp/kept.txt"
grep -q "broken.nff" "$tmp/drop-err.txt" || { cat "$tmp/drop-err.txt" >&2; exit 1; }
python3 "$src/tests/support/png_compare.py" "$tmp/kept.png" "$tmp/cpu.png" $(viewport "$tmp/kept.txt") 20 60 240 400
