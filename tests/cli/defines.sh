#!/usr/bin/env bash
# -D NAME=VALUE on the command line (docs/language.md, params): a param set twice on one command
# line is a usage error naming both values, not "the last one wins".
set -u
plant=$(realpath "${1:?usage: defines.sh PLANT}")
. "$(dirname "$0")/checks.sh"

cat >"$tmp/param.plant" <<'G'
param n = 1;
param m = 2;
axiom: A(n, m);
G
check "-D twice" 64 "$plant" derive -D n=2 -D n=3 "$tmp/param.plant"
contains "-D twice names both" "$tmp/stderr" "-D sets n twice, to 'n=2' and to 'n=3': keep one of them"
lacks "-D twice derives nothing" "$tmp/stdout" "A("
check "-D twice, spelled both ways, on run" 64 "$plant" run "$tmp/param.plant" -D n=2 --define n=3 -o "$tmp/t.txt"
contains "-D twice, run" "$tmp/stderr" "-D sets n twice, to 'n=2' and to 'n=3'"
[ ! -e "$tmp/t.txt" ] && ok || bad "-D twice, run: t.txt was written"
check "-D twice, check" 64 "$plant" check "$tmp/param.plant" -D m=1 -D m=1
contains "-D twice, same value" "$tmp/stderr" "-D sets m twice"
check "-D of two params" 0 "$plant" derive -D n=2 -D m=3 "$tmp/param.plant"
contains "-D of two params" "$tmp/stdout" "A(2,3)"
# a -D value of another type than the param's default: an error at the -D, the default noted
printf 'param r = 1;\nparam v = vec3(1, 1, 1);\nparam b = true;\nmodule A(x);\naxiom: A(r) F(v.x) F(b);\n' >"$tmp/typed.plant"
check "-D vec3 for a number" 65 "$plant" derive "$tmp/typed.plant" -D 'r=vec3(1,2,3)'
contains "-D type, at the -D" "$tmp/stderr" "-D r:1:1: error: 'r' is a number by its default, found a vec3: give a number"
contains "-D type, the default noted" "$tmp/stderr" "typed.plant:1:11: note: the default"
check "-D number for a vec3" 65 "$plant" derive "$tmp/typed.plant" -D v=5
contains "-D number for a vec3, at the -D" "$tmp/stderr" "'v' is a vec3 by its default, found a number"
check "-D number for a bool" 0 "$plant" derive "$tmp/typed.plant" -D b=0
check "-D vec3 for a vec3" 0 "$plant" derive "$tmp/typed.plant" -D 'v=vec3(2,2,2)'
contains "-D vec3 for a vec3 used" "$tmp/stdout" "F(2)"
# more after a -D value's expression: the error is where the more starts
check "-D with junk after the value" 65 "$plant" derive "$tmp/typed.plant" -D 'r=1;'
contains "-D junk, at the junk" "$tmp/stderr" "-D r:1:2: error: expected the end of the value after the expression, found ';'"

echo "defines: $pass passed, $fail failed"
[ $fail -eq 0 ] && [ $pass -gt 0 ]
