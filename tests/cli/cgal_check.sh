#!/usr/bin/env bash
# scripts/cgal-check --quick: three OpenSCAD examples (one imports an STL) meshed by CGAL and
# rendered by Lancer, exact and as the imported mesh, their depths within the tessellation's
# error; every row must pass; then again with --facets (Lancer on OpenSCAD's facets, the
# meshes kept from the first run), at the mesh's rounding. Reported skipped (exit 77, CTest's SKIP_RETURN_CODE) when openscad
# is not installed (scripts/setup.sh installs it).
set -u
LANCER="$1"; SRC="$2"
command -v openscad >/dev/null || { echo "SKIP: no openscad"; exit 77; }
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
"$SRC/scripts/cgal-check" --quick --lancer "$LANCER" --out "$tmp/out" --cache "$tmp/cache" >"$tmp/table" 2>&1
rc=$?
cat "$tmp/table"
[ "$rc" -eq 0 ] || { echo "FAIL: cgal-check exited $rc"; exit 1; }
[ "$(grep -c '| pass |$' "$tmp/table")" -eq 3 ] || { echo "FAIL: not three passing rows"; exit 1; }
"$SRC/scripts/cgal-check" --quick --facets --lancer "$LANCER" --out "$tmp/out" --cache "$tmp/cache" \
  >"$tmp/table" 2>&1
rc=$?
cat "$tmp/table"
[ "$rc" -eq 0 ] || { echo "FAIL: cgal-check --facets exited $rc"; exit 1; }
[ "$(grep -c '| cached | pass |$' "$tmp/table")" -eq 3 ] || { echo "FAIL: not three passing rows"; exit 1; }
# Lancer's facets are OpenSCAD's: every p99 (column 9) within 1e-3.
awk -F'|' 'NR > 2 && $9 + 0 > 1e-3 { exit 1 }' "$tmp/table" || { echo "FAIL: a p99 over 1e-3"; exit 1; }
