#!/usr/bin/env bash
# Malformed NFF and .csg files: `lancer render` exits non-zero with "error: FILE:LINE:COL: what".
set -uo pipefail
LANCER="$1"
dir=$(mktemp -d); trap 'rm -rf "$dir"' EXIT
fail=0
check() {  # check NAME CONTENT EXPECTED-MESSAGE
  printf '%b' "$2" > "$dir/$1"
  err=$("$LANCER" render "$dir/$1" -o "$dir/out.png" 2>&1 >/dev/null); rc=$?
  if [ $rc -eq 0 ]; then echo "FAIL: $1 exited 0"; fail=1; return; fi
  if [ $rc -ge 128 ]; then echo "FAIL: $1 crashed (status $rc)"; fail=1; return; fi
  if [ "$err" != "error: $dir/$3" ]; then echo "FAIL: $1: got '$err', expected 'error: $dir/$3'"; fail=1; fi
  if [ -e "$dir/out.png" ]; then echo "FAIL: $1 wrote an image"; fail=1; fi
}
check truncated.nff 's 0 0 0 1\ns 1 2' 'truncated.nff:2:6: unexpected end of file: expected the sphere centre'
check arity.nff 'p 4\n0 0 0\n1 0 0\n1 1 0\ns 0 0 0 1\n' "arity.nff:5:1: expected a vertex (a finite number), got 's'"
check nan.nff 's 0 0 0 nan\n' "nan.nff:1:9: expected the sphere radius (a finite number), got 'nan'"
check negative.nff 's 0 0 0 -1\n' 'negative.nff:1:9: the sphere radius must be positive'
check huge.nff 'p 99999999999\n' 'huge.nff:1:3: the vertex count 99999999999 is larger than the limit of 1048576'
check truncated.csg 'group() {\n\tcube(size = [1, 2' "truncated.csg:2:19: unexpected end of file: missing ']' for the '[' at $dir/truncated.csg:2:14"
check braces.csg 'group() { cube(); }\n}\n' "braces.csg:2:1: unmatched '}'"
check arity.csg 'sphere(1, 2);' 'arity.csg:1:11: sphere() takes at most 1 positional argument'
check word.csg 'sphere(r = "big");' "word.csg:1:12: expected a number for 'r' of sphere()"
check inf.csg 'cube(size = [1, -inf, 1]);' "inf.csg:1:18: expected a finite number, got '-inf'"
check negative.csg 'cylinder(h = 1, r1 = 1, r2 = -2);' "negative.csg:1:30: 'r2' must not be negative"
check minkowski.csg 'group() {\n\tminkowski() {\n\t\tcube();\n\t}\n}\n' "minkowski.csg:2:2: the node 'minkowski' is not supported (supported: group, union, difference, intersection, render, multmatrix, translate, rotate, scale, mirror, color, cube, sphere, cylinder, linear_extrude, rotate_extrude, square, circle, polygon, polyhedron, hull, text, import, surface)"
deep=$(printf 'group() %.0s' $(seq 1 3000))
check deep.csg "${deep}cube();" 'deep.csg:1:4009: nesting deeper than 500 levels is refused'
# A bad sidecar camera is named too.
printf 'cube();' > "$dir/cam.csg"; printf '{"from": [0, 0, 5], "at": [0, 0, 5]}' > "$dir/cam.camera.json"
err=$("$LANCER" render "$dir/cam.csg" -o "$dir/out.png" 2>&1 >/dev/null); rc=$?
[ $rc -ne 0 ] && [[ "$err" == "error: $dir/cam.camera.json:1:1: camera 'from' and 'at' are the same point" ]] \
  || { echo "FAIL: sidecar error: rc=$rc '$err'"; fail=1; }
[ $fail -eq 0 ] && echo "PASS"
exit $fail
