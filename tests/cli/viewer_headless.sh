#!/usr/bin/env bash
# `lancer view` without a display says so and renders headless. Usage: viewer_headless.sh LANCER SOURCE_DIR
set -euo pipefail
lancer=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
out=$(env -u DISPLAY -u WAYLAND_DISPLAY "$lancer" view builtin:default --width 64 --height 40 \
      --headless-output "$tmp/h.png")
echo "$out"
grep -q "no display" <<<"$out"
test -s "$tmp/h.png"
