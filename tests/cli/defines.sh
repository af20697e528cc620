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

echo "defines: $pass passed, $fail failed"
[ $fail -eq 0 ] && [ $pass -gt 0 ]
