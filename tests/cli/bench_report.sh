#!/usr/bin/env bash
# `lancer bench --report DIR`: DIR/index.html beside the CSV, one page that needs no other file:
# the run (machine, commit, date, command), every plot inline as SVG (its points named, the
# Pareto front), the comparison table with a row for each scheme and peer of each scene (figures,
# or why there are none: "not installed"), and every row of report.csv. POV-Ray's rows are
# checked whether or not povray is installed (LANCER_POVRAY pointing nowhere stands for absent).
set -u
LANCER="$1"; SRC="$2"
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
. "$SRC/tests/support/cli_lib.sh"

scenes=(builtin:default builtin:balls:1)
"$LANCER" bench --quick --report "$tmp/r" --repeats 3 --scenes "${scenes[@]}" --width 40 --height 24 \
  --threads 2 >"$tmp/out" 2>"$tmp/log" || { cat "$tmp/log"; fail "bench --report exited non-zero"; }
page="$tmp/r/index.html"; csv="$tmp/r/report.csv"
[ -s "$page" ] || fail "no index.html"
[ -s "$csv" ] || fail "no report.csv beside the page"
grep -q "wrote $page" "$tmp/out" || fail "bench did not say it wrote the page"

# The run: machine, commit, date and the exact command line.
for th in Date Commit Command CPU Cores Memory Settings; do
  grep -q "<tr><th>$th</th>" "$page" || fail "the page does not say the $th"
done
grep -q -- "--report $tmp/r --repeats 3" "$page" || fail "the command line is not on the page"
grep -q "[0-9]\{4\}-[0-9][0-9]-[0-9][0-9] [0-9:]* UTC" "$page" || fail "no date"
grep -q "3 repeats (round-robin)" "$page" || fail "the repeats are not said"
# Self-contained: nothing loaded from elsewhere (the CSV is a link beside it).
if grep -q -E '<(img|script|link|iframe)[ >]' "$page"; then fail "the page loads another file"; fi

# Every plot, each an inline SVG; the speed-against-error plots name their points.
figures="speed_vs_error-default speed_vs_error-balls-1 progressive regular_max_level push_delta offset precision"
if command -v gnuplot >/dev/null; then
  for f in $figures; do
    awk -v id="$f" 'index($0, "<figure id=\"" id "\">") { on = 1; next } on && /<svg/ { found = 1; exit }
                    on && /<\/figure>/ { exit } END { exit !found }' "$page" || fail "plot $f is not an inline SVG"
  done
  svgs=7
  if command -v openscad >/dev/null && grep -q ',embree,peer (bounces 0),[^,]*,[0-9]' "$csv"; then
    svgs=8  # the mesh axis: exact CSG against OpenSCAD's meshes traced by Embree
    f=exact_vs_mesh-lattice-2
    awk -v id="$f" 'index($0, "<figure id=\"" id "\">") { on = 1; next } on && /<svg/ { found = 1; exit }
                    on && /<\/figure>/ { exit } END { exit !found }' "$page" || fail "plot $f is not an inline SVG"
    for label in "mesh \$fn 8" "mesh \$fn 16" "regular" "bvh" "Pareto front" "pixels hit in one image only" \
                 "depth difference, 99th percentile"; do
      grep -q "$label" "$tmp/r/$f.svg" || fail "$f has no \"$label\""
    done
  fi
  [ "$(grep -c '<svg' "$page")" -eq $svgs ] || fail "expected $svgs SVGs, found $(grep -c '<svg' "$page")"
  for label in "regular (defaults)" "irregular (defaults)" "regular max-level 6" "push delta 0.01" \
               "Pareto front" "pixels whose primary hit differs" "largest depth difference"; do
    grep -q "$label" "$tmp/r/speed_vs_error-balls-1.svg" || fail "speed_vs_error has no \"$label\""
    grep -q "$label" "$page" || fail "the page's speed_vs_error has no \"$label\""
  done
  grep -q "stride 16" "$tmp/r/progressive.svg" || fail "progressive passes are not named"
  # Float against double: the regular scheme in both, brute force in float, named on the plot.
  for label in "render time (ms)" "depth error" ">regular<" ">brute<"; do
    grep -q "$label" "$tmp/r/precision.svg" || fail "precision plot has no \"$label\""
  done
  grep -q "colour RMSE" "$tmp/r/progressive.svg" || fail "progressive plot is not against RMSE"
else
  for f in $figures; do grep -q "<figure id=\"$f\">" "$page" || fail "no figure $f"; done
  grep -q "gnuplot is not installed" "$page" || fail "no word of the missing gnuplot"
fi

# The comparison table: each scene's brute force, schemes and peers.
for s in "${scenes[@]}"; do
  for scheme in brute regular irregular "embree (bounces 0)" "povray (bounces 3)"; do
    grep -q "<tr data-scheme=\"$scheme\"[^>]*><td>$s</td>" "$page" || fail "no table row $s $scheme"
  done
done
grep -q "<tr data-scheme=\"embree (bounces 0)\"[^>]*><td>builtin:default</td><td>embree (bounces 0)</td><td class=\"note\"" "$page" \
  || fail "Embree on a CSG scene: no reason given"
grep -q "<tr data-scheme=\"embree (bounces 0)\"[^>]*><td>builtin:balls:1</td><td>embree (bounces 0)</td><td class=\"n\">" "$page" \
  || grep -q "builtin:balls:1</td><td>embree (bounces 0)</td><td class=\"note\" colspan=\"9\">not installed" "$page" \
  || fail "Embree on a union: neither figures nor \"not installed\""
if command -v povray >/dev/null; then
  # POV-Ray traced each scene: its times, and its depth image agrees with brute force's hits.
  for s in "${scenes[@]}"; do
    grep -q "<td>$s</td><td>povray (bounces 3)</td><td class=\"n\">" "$page" || fail "no POV-Ray figures for $s"
    awk -F, -v s="$s" '$1==s && $2=="povray" { found = 1; if ($15 != 0 || $18 != 3) exit 1 } END { exit !found }' "$csv" \
      || fail "POV-Ray on $s: hits differ from brute force, or not 3 repeats: $(grep povray "$csv")"
  done
  [ -s "$tmp/r/povray/1-default.pov" ] || fail "the .pov file is not kept beside the page"
else
  grep -q "povray (bounces 3)</td><td class=\"note\" colspan=\"9\">not installed" "$page" || fail "no POV-Ray \"not installed\""
fi
# The mesh axis (builtin:lattice:2 by default): every scheme traces the exact solid (no silhouette
# or depth difference from brute force); OpenSCAD's meshes differ, less at the finer $fn.
mesh() { awk -F, -v v="$1" -v c="$2" '$1=="builtin:lattice:2" && $3=="mesh (bounces 0)" && $4==v { print $c }' "$csv"; }
if command -v openscad >/dev/null && [ -n "$(mesh '$fn 8' 26)" ]; then
  for s in regular irregular bvh; do
    awk -F, -v s="$s" '$3=="mesh (bounces 0)" && $2==s { found = 1; if ($15 != 0 || $26 != 0 || $27 != 0 || $28 != 0) exit 1 }
                       END { exit !found }' "$csv" || fail "the exact $s differs from brute force on the mesh axis"
  done
  awk -v a="$(mesh '$fn 8' 27)" -v b="$(mesh '$fn 16' 27)" 'BEGIN { exit !(a > 0 && b > 0 && b < a) }' \
    || fail "the mesh's RMS depth error does not fall from \$fn 8 ($(mesh '$fn 8' 27)) to 16 ($(mesh '$fn 16' 27))"
  awk -v a="$(mesh '$fn 8' 28)" -v b="$(mesh '$fn 16' 28)" 'BEGIN { exit !(a > 0 && b > 0 && b < a) }' \
    || fail "the mesh's 99th-percentile depth error does not fall from \$fn 8 to 16"
  [ "$(mesh '$fn 8' 18)" = 3 ] || fail "the mesh rows were not repeated 3 times"
  [ -s "$tmp/r/openscad/3-lattice-2.scad" ] || fail "the OpenSCAD model is not kept beside the page"
else
  grep -q '^builtin:lattice:2,openscad,mesh (bounces 0),$fn 8,.*\(not installed\|no Embree\)' "$csv" \
    || fail "no mesh row and no reason"
fi
LANCER_OPENSCAD=/nonexistent/openscad "$LANCER" bench --quick --no-plots --out "$tmp/m" --scenes builtin:default \
  --mesh-scenes builtin:drilled:1 --width 16 --height 12 --threads 2 --repeats 1 >/dev/null 2>"$tmp/log" \
  || { cat "$tmp/log"; fail "bench without openscad exited non-zero"; }
grep -q '^builtin:drilled:1,openscad,mesh (bounces 0),$fn 16,.*not installed' "$tmp/m/report.csv" \
  || fail "without openscad: no \"not installed\" mesh row"
grep -q '^builtin:drilled:1,regular,mesh (bounces 0),exact,' "$tmp/m/report.csv" || fail "no exact row on the mesh axis"
if grep -q '^builtin:drilled:1,regular,scheme,' "$tmp/m/report.csv"; then fail "a mesh-axis scene got the sweeps"; fi

# Absent, POV-Ray's rows say so.
LANCER_POVRAY=/nonexistent/povray "$LANCER" bench --schemes-only --no-plots --report "$tmp/n" \
  --scenes builtin:default --width 16 --height 12 --threads 2 --repeats 1 >/dev/null 2>"$tmp/log" \
  || { cat "$tmp/log"; fail "bench --report without povray exited non-zero"; }
grep -q "povray (bounces 3)</td><td class=\"note\" colspan=\"9\">not installed" "$tmp/n/index.html" \
  || fail "without povray: no \"not installed\" row"
grep -q "^builtin:default,povray,.*not installed" "$tmp/n/report.csv" || fail "without povray: no CSV row"
grep -q "| povray (bounces 3) | not installed" "$tmp/n/schemes.md" || fail "without povray: no markdown row"
grep -q "No plots" "$tmp/n/index.html" || fail "--no-plots: the page does not say there are none"

# Every row of report.csv is a row of the page's full table, with its scene, scheme and knob.
rows=$(($(wc -l <"$csv") - 1))
[ "$(grep -c '<tr data-row=' "$page")" -eq "$rows" ] || fail "the page has not the CSV's $rows rows"
tail -n +2 "$csv" | awk -F, '{ print NR "\t" $1 "\t" $2 "\t" $3 "\t" $4 }' | \
while IFS=$'\t' read -r n scene scheme knob value; do
  grep -qF "<tr data-row=\"$n\"><td>$scene</td><td>$scheme</td><td>$knob</td><td>$value</td>" "$page" \
    || fail "CSV row $n ($scene $scheme $knob $value) is not on the page"
done || exit 1
# Float against double: the regular scheme in double makes no error; in float (and brute force
# in float) its hits move by single precision's rounding, on every scene.
for s in "${scenes[@]}"; do
  awk -F, -v s="$s" '$1==s && $3=="precision" && $2=="regular" && $4=="double" { found = 1; if ($15 != 0 || $17 != 0) exit 1 }
                     END { exit !found }' "$csv" || fail "$s: the regular scheme in double differs from brute force"
  for scheme in regular brute; do
    awk -F, -v s="$s" -v k="$scheme" '$1==s && $3=="precision" && $2==k && $4=="float" { found = 1; if (!($28 > 0 && $28 < 1e-3)) exit 1 }
                       END { exit !found }' "$csv" || fail "$s: $scheme in float has no row or no small depth error"
  done
done
# Measured rows: three repeats, a median within its range.
awk -F, 'NR > 1 && $18 != "" { if ($18 != 3 || $8 < $21 || $8 > $22) { print; exit 1 } }' "$csv" \
  || fail "a row's median is not within its range, or not 3 repeats"

fails "--repeats" "$LANCER" bench --repeats 0 --report "$tmp/z"

# `lancer export --scad`: the OpenSCAD model the mesh axis meshes; surfaces refused, no file left.
"$LANCER" export builtin:lattice:2 --scad "$tmp/l.scad" --fn 12 >"$tmp/out" || fail "export --scad failed"
grep -q '^\$fn = 12;' "$tmp/l.scad" || fail "export --scad: no \$fn = 12"
grep -q 'difference() {' "$tmp/l.scad" || fail "export --scad: no difference"
fails "give --pov FILE.pov, --scad FILE.scad" "$LANCER" export builtin:default
fails "OpenSCAD models solids only" "$LANCER" export "$SRC/assets/spd/balls1.nff" --scad "$tmp/s.scad"
[ ! -e "$tmp/s.scad" ] || fail "a refused export left a file"
echo ok
