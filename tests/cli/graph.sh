#!/usr/bin/env bash
# plant graph, --edits and the Fig. 10 sequence of Boudon et al. 2003 (docs/language.md,
# decomposition graphs): real values, statuses and origins; range matching keeps the edit of the
# bottom branch through density 3 -> 4 -> 3, single-position matching leaves it dormant at 4.
set -u
plant=$(realpath "${1:?usage: graph.sh PLANT}")
root=$(cd "$(dirname "$0")/../.." && pwd)
. "$(dirname "$0")/checks.sh"
range=$root/grammars/bonsai/fig10_range.plant
single=$root/grammars/bonsai/fig10_single.plant
curved="bend(0..1) = 0 0.2 0.4 0.6000000000000001 0.8  (explicit, public, from"
straight="bend(0..1) = 0 0 0 0 0  (inherited, public, from /)"

check "graph --help" 0 "$plant" graph --help
contains "graph --help names --json" "$tmp/stdout" "--json"
contains "graph --help names --edits" "$tmp/stdout" "--edits"
check "help lists graph" 0 "$plant" help
contains "help lists graph" "$tmp/stdout" "graph"

# Fig. 10 a/b: three laterals, the bottom one (0.25) carries the edit of fig10.edits (the default)
check "fig10 range, density 3" 0 "$plant" graph "$range"
contains "three laterals" "$tmp/stdout" "  /0.75"
grep -A1 '^  /0.25$' "$tmp/stdout" >"$tmp/n"
contains "bottom branch curved at 3" "$tmp/n" "$curved /0.25)"
grep -A1 '^  /0.5$' "$tmp/stdout" >"$tmp/n"
contains "middle branch inherits the root's straight bend" "$tmp/n" "$straight"
contains "the edit applies to /0.25" "$tmp/stdout" "fig10.edits:4:1: /0.25[0..0.375] bend: applies to /0.25"
# Fig. 10 c with range matching: the branch at 0.2 carries the edit
check "fig10 range, density 4" 0 "$plant" graph "$range" -D density=4
grep -A1 '^  /0.2$' "$tmp/stdout" >"$tmp/n"
contains "the branch at 0.2 is curved" "$tmp/n" "$curved /0.2)"
for p in 0.4 0.6 0.8; do
  grep -A1 "^  /$p\$" "$tmp/stdout" >"$tmp/n"
  contains "the branch at $p is straight" "$tmp/n" "$straight"
done
contains "range: the edit applies to /0.2" "$tmp/stdout" "applies to /0.2"
# density back to three: curved again
check "fig10 range, density 3 again" 0 "$plant" graph "$range" -D density=3
grep -A1 '^  /0.25$' "$tmp/stdout" >"$tmp/n"
contains "curved again at 3" "$tmp/n" "$curved /0.25)"
# single-position matching: curved at 3, lost at 4 (dormant), and check says so
check "fig10 single, density 3" 0 "$plant" graph "$single"
grep -A1 '^  /0.25$' "$tmp/stdout" >"$tmp/n"
contains "single: curved at 3" "$tmp/n" "$curved /0.25)"
check "fig10 single, density 4" 0 "$plant" graph "$single" -D density=4
lacks "single: no branch is curved at 4" "$tmp/stdout" "0.2 0.4"
contains "single: the edit is dormant at 4" "$tmp/stdout" "bend: dormant"
check "check single density 4" 0 "$plant" check "$single" -D density=4
contains "check reports the dormant edit" "$tmp/stderr" "fig10.edits:4:1: warning: dormant edit"
check "check range density 4" 0 "$plant" check "$range" -D density=4
lacks "range: nothing dormant" "$tmp/stderr" "dormant"

# --json: the same graph, parsed
check "graph --json" 0 "$plant" graph "$range" -D density=4 --json
python3 - "$tmp/stdout" <<'PY' && pass=$((pass + 1)) || { fail=$((fail + 1)); echo "FAIL graph --json values"; }
import json, sys
g = json.load(open(sys.argv[1]))
nodes = {n["path"]: n for n in g["nodes"]}
assert g["match"] == "range", g["match"]
assert list(nodes) == ["/", "/0.2", "/0.4", "/0.6", "/0.8"], list(nodes)
b = nodes["/0.2"]["params"]["bend"]
assert b["status"] == "explicit" and b["from"] == "/0.2" and abs(b["value"][4] - 0.8) < 1e-12, b
assert nodes["/0.4"]["params"]["bend"] == {"value": [0, 0, 0, 0, 0], "status": "inherited", "private": False, "from": "/"}
assert g["edits"][0]["node"] == "/0.2" and g["edits"][0]["path"] == "/0.25[0..0.375]", g["edits"]
PY

# --edits replaces the grammar's default: run and derive apply it
printf '/0.5[0.4..0.6] bend = linear(1, 1)\n/0.5 bend private\n' >"$tmp/mid.edits"
check "derive default" 0 "$plant" derive "$range"
cp "$tmp/stdout" "$tmp/default.txt"
check "derive --edits" 0 "$plant" derive "$range" --edits "$tmp/mid.edits"
contains "derive --edits bends the middle branch" "$tmp/stdout" "-(25)F(0.2)"
check "run --edits" 0 "$plant" run "$range" --edits "$tmp/mid.edits" -o "$tmp/mid.txt"
if cmp -s "$tmp/stdout" "$tmp/mid.txt" || ! diff -q <(tr -d '\n' <"$tmp/mid.txt") <("$plant" derive "$range" --edits "$tmp/mid.edits" | tr -d '\n') >/dev/null; then
  fail=$((fail + 1)); echo "FAIL run --edits writes what derive --edits prints"
else pass=$((pass + 1)); fi
check "graph --edits" 0 "$plant" graph "$range" --edits "$tmp/mid.edits"
grep -A1 '^  /0.5$' "$tmp/stdout" >"$tmp/n"
contains "graph shows the private explicit edit" "$tmp/n" "bend(0..1) = 1 1 1 1 1  (explicit, private, from /0.5)"
grep -A1 '^  /0.25$' "$tmp/stdout" >"$tmp/n"
contains "the default edits are replaced" "$tmp/n" "$straight"

# the REPL: edits typed, then :save; plant run --edits of the saved file writes the same plant, byte
# for byte, as the REPL's :export
printf ':step 2\n:set density 4\n:edit /0.6 bend = linear(0, 1)\n:private /0.2 bend\n:export %s\n:save %s\n' \
  "$tmp/repl.txt" "$tmp/repl.edits" >"$tmp/script"
check "repl edits and :save" 0 "$plant" repl "$range" <"$tmp/script"
contains "repl wrote the edits" "$tmp/stdout" "wrote $tmp/repl.edits (6 lines)"
contains "saved with the node's range" "$tmp/repl.edits" "/0.6[0.5..0.7] bend = linear(0, 1)"
check "run the saved edits" 0 "$plant" run "$range" -D density=4 --edits "$tmp/repl.edits" -o "$tmp/run.txt"
if cmp -s "$tmp/repl.txt" "$tmp/run.txt" && grep -q -- "-(3.125)F(0.2)" "$tmp/run.txt"; then pass=$((pass + 1)); else
  fail=$((fail + 1)); echo "FAIL :save then plant run --edits gives the REPL's plant"; fi

# errors: a missing --edits file, edits for a grammar without graph, a malformed edits file
check "missing --edits file" 66 "$plant" derive "$range" --edits "$tmp/none.edits"
contains "missing --edits names the file" "$tmp/stderr" "cannot read the edits file"
printf 'axiom: F;\n' >"$tmp/plain.plant"
check "--edits without a graph" 64 "$plant" derive "$tmp/plain.plant" --edits "$tmp/mid.edits"
check "graph without a graph" 64 "$plant" graph "$tmp/plain.plant"
printf '/0.25 bend = 1\n/0.5 bent = linear(0, 1)\n' >"$tmp/bad.edits"
check "malformed edits" 65 "$plant" run "$range" --edits "$tmp/bad.edits" -o "$tmp/bad.txt"
contains "malformed edits: file:line:col" "$tmp/stderr" "bad.edits:2:6: error: the graph has no parameter 'bent'; did you mean 'bend'?"
contains "malformed edits: caret" "$tmp/stderr" "^~~~"
if [ -e "$tmp/bad.txt" ]; then fail=$((fail + 1)); echo "FAIL malformed edits wrote a file"; else pass=$((pass + 1)); fi
# a number literal out of range in an edits file is an error there, as in a grammar (it was 0)
printf '/0.25 bend = 1e309\n' >"$tmp/huge.edits"
check "an out-of-range literal in edits" 65 "$plant" derive "$range" --edits "$tmp/huge.edits"
contains "the literal's place" "$tmp/stderr" "huge.edits:1:14: error: number '1e309' is out of range"
# more after an edit's value: the error is at the more, not over the whole value
printf '/0.25 bend = linear(0, 1) extra\n' >"$tmp/junk.edits"
check "junk after an edit's value" 65 "$plant" derive "$range" --edits "$tmp/junk.edits"
contains "the junk's place" "$tmp/stderr" "junk.edits:1:27: error: expected the end of the value after the expression, found 'extra'"
# the grammar's own `edits "FILE";` naming a pipe: refused at that statement
mkdir -p "$tmp/fifo" && mkfifo "$tmp/fifo/p.edits"
printf 'graph { len = 1; }\nedits "p.edits";\nmodule Axis(n: node);\naxiom: Axis(root());\n' >"$tmp/fifo/g.plant"
check "an edits file that is a pipe" 66 timeout 10 "$plant" derive "$tmp/fifo/g.plant"
contains "the pipe, at the grammar's statement" "$tmp/stderr" "g.plant:2:7: error: cannot read the edits file"

echo "graph CLI: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
