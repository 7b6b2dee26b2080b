#!/usr/bin/env bash
# Bad input to render, trace, view and structure: a directory or a missing file given as SCENE
# is refused by name with status 2; the viewer's options that cannot apply (a layer the scheme
# has not, --ab without --change, a playback step without --pick) are refused before any window
# opens; help-options is listed. Usage: bad_input_cli.sh LANCER SOURCE_DIR
set -euo pipefail
lancer=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
source "$2/tests/support/cli_lib.sh"
mkdir "$tmp/x.nff"
for cmd in render trace view structure; do
  case $cmd in
    render) extra=(-o "$tmp/out.png") ;;
    trace) extra=(--pixel 1 1) ;;
    view) extra=(--frames 1 --ini none) ;;
    structure) extra=(-o "$tmp/out.json") ;;
  esac
  fails "$tmp/x.nff: is a directory" "$lancer" "$cmd" "$tmp/x.nff" "${extra[@]}"
  fails "/no/such/file.nff: no such file" "$lancer" "$cmd" /no/such/file.nff "${extra[@]}"
  fails "/no/such/file: no such file" "$lancer" "$cmd" /no/such/file "${extra[@]}"
  # Nothing was written, and nothing claims success.
  [ ! -e "$tmp/out.png" ] && [ ! -e "$tmp/out.json" ] || { echo "$cmd wrote an output" >&2; exit 1; }
  ! grep -q "rendered\|structure of\|headless" "$tmp/out.txt" || { cat "$tmp/out.txt" >&2; exit 1; }
done
# A directory given as --camera is named too.
fails "$tmp/x.nff: is a directory" "$lancer" render builtin:default --camera "$tmp/x.nff" -o "$tmp/out.png"
# The viewer's options, checked before any window opens (no display needed).
fails "--show leaves: the irregular scheme has no leaves" \
  "$lancer" view builtin:default --scheme irregular --show leaves,grid --frames 1 --ini none
fails "--show zones: the regular scheme has no zones" \
  "$lancer" view builtin:default --scheme regular --show zones --frames 1 --ini none
fails "--ab diff: .* needs --change" "$lancer" view builtin:default --ab diff --frames 1 --ini none
fails "--step first: a playback step" "$lancer" view builtin:default --step first --frames 1 --ini none
fails "--step last: a playback step" "$lancer" view builtin:default --step last --frames 1 --ini none
# help-options is listed in the help, and prints the options table. Each output is read from a
# file: `grep -q` quits at its match, and with pipefail the writer's SIGPIPE would fail the test.
"$lancer" --help > "$tmp/help.txt"
grep -q "help-options" "$tmp/help.txt" || { echo "help-options not in lancer --help" >&2; exit 1; }
"$lancer" help-options > "$tmp/options.md"
grep -q -- "| \`--max-objects N\` |" "$tmp/options.md" || { echo "help-options output" >&2; exit 1; }
# --step's two meanings are told apart in view's help.
"$lancer" view --help > "$tmp/view.txt"
tr -s ' \n' ' ' < "$tmp/view.txt" > "$tmp/view1.txt"
grep -q "Without --pick: the regular scheme's next-cell method" "$tmp/view1.txt" \
  || { echo "view --help does not tell --step's meanings apart" >&2; exit 1; }
echo ok
