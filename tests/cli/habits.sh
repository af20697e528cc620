#!/bin/bash
# Habits from ABOP, cpfg and L-Py that script directives cannot see: the note for a grammar with
# rules and no `derive N;` (none when -n gives the steps), and a non-ASCII character shown as itself under its caret.
set -u
plant="$1"
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail=0
check() { # name, expected substring, actual text
    if [[ "$3" != *"$2"* ]]; then
        echo "FAIL $1: expected to find: $2"
        echo "got: $3"
        fail=1
    fi
}
printf 'axiom: A;\nrules { A -> F A; }\n' >"$dir/no_derive.plant"
out=$("$plant" check "$dir/no_derive.plant" 2>&1)
check no_derive "no_derive.plant:2:9: note: the grammar has rules but no 'derive N;': it derives 0 steps unless given -n; add a line such as 'derive 5;'" "$out"
# with -n the steps are given: no note, from derive or from check (which takes a run's options)
out=$("$plant" derive "$dir/no_derive.plant" -n 2 2>&1)
[[ "$out" == "FFA" ]] || { echo "FAIL derive -n: the note, or not FFA: $out"; fail=1; }
out=$("$plant" check "$dir/no_derive.plant" -n 2 --seed 3 --threads 1 2>&1)
[[ -z "$out" ]] || { echo "FAIL check -n --seed --threads: $out"; fail=1; }
printf 'derive 1;\naxiom: A;\nrules { A -> F α; }\n' >"$dir/alpha.plant"
out=$("$plant" check "$dir/alpha.plant" 2>&1)
check alpha_message "alpha.plant:3:16: error: expected ';' after production (started at 3:9), found 'α' (U+03B1)" "$out"
check alpha_line "    3 | rules { A -> F α; }" "$out"
check alpha_caret "      |                ^" "$out"
exit $fail
