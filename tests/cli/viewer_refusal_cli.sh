#!/usr/bin/env bash
# `lancer view` under Xvfb with a structure the options make impossible: refused at start, the
# run ends with status 2 naming the options, and no brute-force image stands in for it (no
# screenshot, no success line). A live change to a refused structure keeps what is shown.
# Usage: viewer_refusal_cli.sh LANCER SOURCE_DIR
set -euo pipefail
lancer=$1
xvfb_run="$(dirname "$0")/xvfb_run"  # xvfb-run -a (it says when xvfb is missing)
src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
source "$src/tests/support/cli_lib.sh"
# -noreset: Xvfb signals xvfb-run again when its last client leaves, which can fail
# xvfb-run's clean-up (status 5) when the viewer exits at once.
run() { timeout 240 "$xvfb_run" -s "-screen 0 1920x1080x24 -noreset" "$lancer" view "$@" --width 320 \
  --height 200 --frames 3 --ini none --screenshot "$tmp/shot.png"; }
fails "the structure was refused: --max-level 48 --max-objects 1" \
  run "$src/assets/spd/balls4.nff" --max-level 48 --max-objects 1 --no-cost-stop
grep -q "BSP nodes" "$tmp/err.txt" || { cat "$tmp/err.txt" >&2; exit 1; }
[ ! -e "$tmp/shot.png" ] || { echo "a refused start wrote a screenshot" >&2; exit 1; }
! grep -q "screenshot\|brute" "$tmp/out.txt" "$tmp/err.txt" || { cat "$tmp/out.txt" "$tmp/err.txt" >&2; exit 1; }
fails "the structure was refused: --memory-budget 256" \
  run "$src/assets/openscad/sponge.csg" --scheme regular --memory-budget 256K
[ ! -e "$tmp/shot.png" ] || { echo "a refused start wrote a screenshot" >&2; exit 1; }
# A live change to a structure that is refused keeps the one on screen: the run goes on.
rm -f "$tmp/shot.png"
run builtin:default --change max-level=48,max-objects=1 >"$tmp/live.txt" 2>"$tmp/live_err.txt"
grep -q "Structure not built: --max-level 48 --max-objects 1" "$tmp/live_err.txt" \
  || { cat "$tmp/live_err.txt" >&2; exit 1; }
test -s "$tmp/shot.png"
# The same options on a structure that fits: the run succeeds.
run builtin:default --max-level 8 --max-objects 1 >"$tmp/ok.txt"
test -s "$tmp/shot.png"
grep -q "screenshot" "$tmp/ok.txt"
echo ok
