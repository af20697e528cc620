#!/bin/bash
# Habits from ABOP, cpfg and L-Py that script directives cannot see: the note for a grammar with
# rules and no `derive N;`, and a non-ASCII character shown as itself under its caret.
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
printf 'derive 1;\naxiom: A;\nrules { A -> F α; }\n' >"$dir/alpha.plant"
out=$("$plant" check "$dir/alpha.plant" 2>&1)
check alpha_message "alpha.plant:3:16: error: expected ';' after production (started at 3:9), found 'α' (U+03B1)" "$out"
check alpha_line "    3 | rules { A -> F α; }" "$out"
check alpha_caret "      |                ^" "$out"
exit $fail
