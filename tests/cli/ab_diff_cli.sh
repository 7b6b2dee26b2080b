#!/usr/bin/env bash
# The rebuild A/B from the command line: `--view`, `--ab` and `--change` refuse what they do not
# know with status 2 naming the option, before any window opens; under Xvfb a run that changes
# max-level after the first image and shows the diff writes its screenshot and succeeds.
# Usage: ab_diff_cli.sh LANCER SOURCE_DIR
set -euo pipefail
lancer=$1
xvfb_run="$(dirname "$0")/xvfb_run"  # xvfb-run -a (it says when xvfb is missing)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
source "$2/tests/support/cli_lib.sh"
fails "--view" "$lancer" view builtin:default --view heat --frames 1 --ini none
fails "--ab" "$lancer" view builtin:default --ab both --frames 1 --ini none
fails "--change" "$lancer" view builtin:default --change max-level=99 --frames 1 --ini none
fails "--change" "$lancer" view builtin:default --change depth=x.pfm --frames 1 --ini none
fails "--change" "$lancer" view builtin:default --change max-level --frames 1 --ini none
timeout 240 "$xvfb_run" -s "-screen 0 800x600x24" "$lancer" view builtin:balls:1 --width 320 \
  --height 200 --frames 3 --ini none --max-level 3 --change max-level=8,max-objects=2 \
  --view prim_tests --ab diff --hide-panels --screenshot "$tmp/diff.png"
test -s "$tmp/diff.png"
