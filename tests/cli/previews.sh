#!/usr/bin/env bash
# Previews and mesh files that look like the book (issue 20): --width-scale and the grammar's
# width_scale, --view and --lines, --size and --sides for SVG, OBJ materials and groups, PLY
# vertex colours.
set -u
plant=$(realpath "${1:?usage: previews.sh PLANT}")
src=$(cd "$(dirname "$0")/../.." && pwd)
. "$(dirname "$0")/checks.sh"
abop=$src/grammars/abop

# width: the grammar's width_scale, and --width-scale over it
check "honda" 0 "$plant" run "$abop/fig2_6a.plant" -o "$tmp/h.mesh.txt"
contains "width_scale 0.02 in the grammar" "$tmp/h.mesh.txt" "bounds -1.7109 0.0000 -2.6000 1.7871 6.5132 1.6920"
check "honda --width-scale 1" 0 "$plant" run "$abop/fig2_6a.plant" --width-scale 1 -o "$tmp/h1.mesh.txt"
contains "--width-scale 1: ABOP's widths as model units" "$tmp/h1.mesh.txt" "bounds -5.0000 -1.4996 -5.0000 5.0000"
check "--width-scale 0" 64 "$plant" run "$abop/fig2_6a.plant" --width-scale 0 -o "$tmp/x.glb"
printf 'width_scale 0;\naxiom: F;\n' >"$tmp/zero.plant"
check "width_scale 0" 65 "$plant" check "$tmp/zero.plant"
contains "width_scale 0 is an error at the number" "$tmp/stderr" "zero.plant:1:13: error: width_scale must be a number above 0"
printf 'param s = 1;\nwidth_scale s - 1;\naxiom: F;\n' >"$tmp/zero_param.plant"
check "width_scale from a param, 0" 70 "$plant" run "$tmp/zero_param.plant" -o "$tmp/x.glb"
contains "width_scale 0 at run time" "$tmp/stderr" "width_scale must be a number above 0"

# views
check "--view front" 0 "$plant" run "$abop/fig2_6a.plant" --view front --size 64x64 -o "$tmp/front.png"
check "--view top" 0 "$plant" run "$abop/fig2_6a.plant" --view top --size 64x64 -o "$tmp/top.png"
check "--view side" 0 "$plant" run "$abop/fig2_6a.plant" --view side --size 64x64 -o "$tmp/side.png"
check "--view iso" 0 "$plant" run "$abop/fig2_6a.plant" --view iso --size 64x64 -o "$tmp/iso.png"
check "default view" 0 "$plant" run "$abop/fig2_6a.plant" --size 64x64 -o "$tmp/auto.png"
if cmp -s "$tmp/auto.png" "$tmp/iso.png"; then ok; else bad "a 3-D tree is drawn 3/4 by default"; fi
for v in front top side; do
  if ! cmp -s "$tmp/$v.png" "$tmp/iso.png"; then ok; else bad "--view $v is the iso view"; fi
done
check "koch default" 0 "$plant" run "$abop/fig1_9a.plant" --size 64x64 -o "$tmp/k_auto.png"
check "koch front" 0 "$plant" run "$abop/fig1_9a.plant" --view front --size 64x64 -o "$tmp/k_front.png"
if cmp -s "$tmp/k_auto.png" "$tmp/k_front.png"; then ok; else bad "a flat figure is drawn face-on by default"; fi
check "koch --tubes" 0 "$plant" run "$abop/fig1_9a.plant" --tubes --size 64x64 -o "$tmp/k_tubes.png"
check "koch --lines" 0 "$plant" run "$abop/fig1_9a.plant" --lines --size 64x64 -o "$tmp/k_lines.png"
if cmp -s "$tmp/k_auto.png" "$tmp/k_lines.png"; then ok; else bad "hairline tubes are drawn as lines by default"; fi
if ! cmp -s "$tmp/k_tubes.png" "$tmp/k_lines.png"; then ok; else bad "--tubes draws lines"; fi
check "--lines --tubes" 64 "$plant" run "$abop/fig1_9a.plant" --lines --tubes -o "$tmp/x.png"
check "bad --view" 64 "$plant" run "$abop/fig1_9a.plant" --view back -o "$tmp/x.png"
contains "bad --view names the views" "$tmp/stderr" "--view expects front, top, side, iso or auto, found 'back'"
check "--view with --camera" 64 "$plant" run "$abop/fig1_9a.plant" --view top --camera 0,0,10 -o "$tmp/x.png"
if [ ! -e "$tmp/x.png" ]; then ok; else bad "output after a usage error"; fi

# SVG: --size is honoured, --sides said to be unused
check "svg --size" 0 "$plant" run "$abop/fig1_9a.plant" --size 300x200 -o "$tmp/k.svg"
contains "svg width and height" "$tmp/k.svg" 'width="300" height="200"'
check "svg default" 0 "$plant" run "$abop/fig1_9a.plant" -o "$tmp/k800.svg"
contains "svg default width" "$tmp/k800.svg" 'width="800"'
check "svg --sides" 0 "$plant" run "$abop/fig1_9a.plant" --sides 6 -o "$tmp/k6.svg"
contains "svg --sides warns" "$tmp/stderr" "warning: --sides shapes meshed tubes; an .svg is a line drawing"
check "svg and glb --sides" 0 "$plant" run "$abop/fig1_9a.plant" --sides 6 -o "$tmp/k6b.svg" -o "$tmp/k6.glb"
lacks "--sides used by the glb: no warning" "$tmp/stderr" "warning"

# OBJ: a .mtl beside it, with the preview's colours; objects per organ kind
check "rose obj" 0 "$plant" run "$src/grammars/rose/fig12c.plant" -o "$tmp/rose.obj" -o "$tmp/rose.ply"
contains "mtllib" "$tmp/rose.obj" "mtllib rose.mtl"
contains "branches object" "$tmp/rose.obj" "o branches"
contains "leaflet object" "$tmp/rose.obj" "o leaflet"
contains "leaflet group" "$tmp/rose.obj" "g leaflet"
# the material the leaflets use, and its colour: green
leaf_mtl=$(awk '/^o leaflet/ { on = 1 } on && /^usemtl/ { print $2; exit }' "$tmp/rose.obj")
leaf_kd=$(awk -v m="$leaf_mtl" '$1 == "newmtl" { on = ($2 == m) } on && $1 == "Kd" { print $2, $3, $4; exit }' "$tmp/rose.mtl")
if [ -n "$leaf_kd" ] && awk -v c="$leaf_kd" 'BEGIN { split(c, k, " "); exit !(k[2] > k[1] && k[2] > k[3]) }'; then ok; else
  bad "the rose's leaflet material '$leaf_mtl' is not green: Kd '$leaf_kd'"
fi
petal_mtl=$(awk '/^o petal/ { on = 1 } on && /^usemtl/ { print $2; exit }' "$tmp/rose.obj")
petal_kd=$(awk -v m="$petal_mtl" '$1 == "newmtl" { on = ($2 == m) } on && $1 == "Kd" { print $2, $3, $4; exit }' "$tmp/rose.mtl")
if [ -n "$petal_kd" ] && awk -v c="$petal_kd" 'BEGIN { split(c, k, " "); exit !(k[1] > k[2] && k[1] > 0.5) }'; then ok; else
  bad "the rose's petal material '$petal_mtl' is not red or pink: Kd '$petal_kd'"
fi
# every usemtl names a material of the .mtl; faces as many as the scene's triangles
for m in $(grep '^usemtl' "$tmp/rose.obj" | awk '{ print $2 }' | sort -u); do
  if grep -qx "newmtl $m" "$tmp/rose.mtl"; then ok; else bad "usemtl $m not in the .mtl"; fi
done
contains "PLY vertex colours" "$tmp/rose.ply" "property uchar red"
# all or nothing: the .mtl is not left behind when another output fails
check "obj with an unwritable output" 73 "$plant" run "$abop/fig1_9a.plant" -o "$tmp/t/k.obj" -o /proc/nope/x.png
mkdir -p "$tmp/t"
check "obj with an unwritable output, folder there" 73 "$plant" run "$abop/fig1_9a.plant" -o "$tmp/t/k.obj" -o /proc/nope/x.png
if [ -z "$(ls -A "$tmp/t")" ]; then ok; else bad "files left behind: $(ls -A "$tmp/t")"; fi

echo "previews: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
