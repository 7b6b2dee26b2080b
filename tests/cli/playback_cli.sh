#!/usr/bin/env bash
# The viewer's ray playback from the command line: `--pick X Y [--ray K] --step first|last|N`
# under Xvfb stops the playback at step N of ray K (the screenshot is written, the run
# succeeds), a pick or a ray or step that does not exist fails with status 2 naming the option
# and writes no screenshot, and `--step` keeps its meaning of next-cell method (exact, push)
# when it is one of those words. Usage: playback_cli.sh LANCER
# SOURCE_DIR
set -euo pipefail
lancer=$1
xvfb_run="$(dirname "$0")/xvfb_run"  # xvfb-run -a (it says when xvfb is missing)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
source "$2/tests/support/cli_lib.sh"
# Checked before any window opens.
fails "--step 3" "$lancer" view builtin:default --step 3 --frames 1 --ini none
fails "--step sideways" "$lancer" view builtin:default --step sideways --frames 1 --ini none
fails "--pick" "$lancer" view builtin:default --ray 1 --frames 1 --ini none
# --width and --height are the image viewport's: the window (panels beside it) fits the screen.
run() { timeout 240 "$xvfb_run" -s "-screen 0 1920x1080x24" "$lancer" view builtin:default \
  --width 640 --height 400 --frames 3 --ini none "$@"; }
fails "--show" run --show rays
fails "--pick" run --pick 5000 10
fails "--ray 999" run --pick 320 200 --ray 999
fails "--step 100000" run --pick 320 200 --step 100000 --screenshot "$tmp/bad.png"
# A failing step writes no screenshot and does not say it did.
[ ! -e "$tmp/bad.png" ] || { echo "a failed --step wrote a screenshot" >&2; exit 1; }
! grep -q "screenshot" "$tmp/out.txt" || { cat "$tmp/out.txt" >&2; exit 1; }
# first and last: the ray's first region (step 0) and its final one.
run --scheme irregular --pick 320 200 --step first --screenshot "$tmp/first.png" >"$tmp/first.txt"
grep -q "ray 0 at step 0 of [0-9]" "$tmp/first.txt" || { cat "$tmp/first.txt" >&2; exit 1; }
run --scheme irregular --pick 320 200 --step last --screenshot "$tmp/last.png" >"$tmp/last.txt"
steps=$(sed -n 's/.*ray 0 at step [0-9]* of \([0-9]*\).*/\1/p' "$tmp/last.txt")
grep -q "ray 0 at step $((steps - 1)) of $steps" "$tmp/last.txt" || { cat "$tmp/last.txt" >&2; exit 1; }
[ "$steps" -gt 1 ] || { echo "the picked ray crosses one region: first and last are the same" >&2; exit 1; }
run --scheme irregular --pick 320 200 --step 1 --show ray,inspector --screenshot "$tmp/p.png"
test -s "$tmp/p.png"
