#!/usr/bin/env bash
# plant test itself (docs/testing.md): the worked example project, --bless listing the files
# it writes with a short diff, libraries in subfolders left out, and how `# expect error:`
# matches a message given without its position or suggestion, or by `contains:`.
set -u
plant=$(realpath "${1:?usage: plant_test.sh PLANT}")
src=$(cd "$(dirname "$0")/../.." && pwd)
. "$(dirname "$0")/checks.sh"

cp -r "$src/examples/testing" "$tmp/project"
cd "$tmp/project" || exit 1
"$plant" test --allow-read lib . -v >"$tmp/out" 2>&1
if [ $? -eq 0 ]; then ok; else bad "the example project fails"; cat "$tmp/out"; fi
contains "the library is named as one" "$tmp/out" "library ./lib/branching.plant (imported, not a test)"
contains "all pass" "$tmp/out" "8 passed, 0 failed"

# --bless: each file written, with a short diff; the library gets no sidecar
sed -i 's/^param spread = 25;/param spread = 30;/' lib/branching.plant
"$plant" test --allow-read lib . >"$tmp/out" 2>&1
if [ $? -eq 1 ]; then ok; else bad "a changed string passes"; fi
"$plant" test --allow-read lib --bless . >"$tmp/out" 2>&1
contains "bless names the file" "$tmp/out" "wrote ./bush.txt"
contains "the old line" "$tmp/out" "    1 - F[+(25)F[+(25)"
contains "the new line" "$tmp/out" "    1 + F[+(30)F[+(30)"
contains "the mesh summary too" "$tmp/out" "wrote ./bush.mesh.txt"
contains "its changed line only" "$tmp/out" "    5 + bounds -2.2408 0.0000"
lacks "its unchanged lines left out" "$tmp/out" "+ vertices"
contains "bless counts files" "$tmp/out" "2 files written"
lacks "no sidecars" "$tmp/out" "sidecar"
if [ ! -e lib/branching.txt ]; then ok; else bad "--bless wrote a golden file for the library"; fi
"$plant" test --allow-read lib . >"$tmp/out" 2>&1
if [ $? -eq 0 ]; then ok; else bad "after --bless the project fails"; cat "$tmp/out"; fi
# named on the command line, a library is run (and fails: it has no axiom)
"$plant" test --allow-read lib lib/branching.plant >"$tmp/out" 2>&1
if [ $? -eq 1 ]; then ok; else bad "a library named on the command line is not run"; fi

# matching: a wrong message still fails, with or without the position
mkdir "$tmp/m"
cd "$tmp/m" || exit 1
body='param spread = 25;\nmodule X;\naxiom: +(sprad) X;\n'
t() { printf "# command: check\n# expect error%s\n$body" "$1" >"$2.plant"; }
t ": unknown name 'sprad'; did you mean 'spread'?" no_position
t ": unknown name 'sprad'" no_suggestion
t ": 5:10: unknown name 'sprad'" no_suggestion_placed
t " contains: 'sprad'" contains
t ": unknown name 'spread'" wrong_name
t ": 5:11: unknown name 'sprad'" wrong_column
t ": unknown name" cut_mid_message
t " contains: 'sprod'" wrong_contains
"$plant" test --allow-read lib . -v >"$tmp/out" 2>&1
for f in no_position no_suggestion no_suggestion_placed contains; do contains "$f matches" "$tmp/out" "ok ./$f.plant"; done
for f in wrong_name wrong_column cut_mid_message wrong_contains; do contains "$f fails" "$tmp/out" "FAIL ./$f.plant"; done
contains "a contains expectation is shown as one" "$tmp/out" "expected: containing: 'sprod'"

# a directive mistyped (`# expcet:`) fails the test, naming the directive, instead of being a comment
mkdir -p "$tmp/typo" && printf 'derive 1;\naxiom: F;\n# expcet: F\n# Note: a comment\n' >"$tmp/typo/one.plant"
(cd "$tmp/typo" && "$plant" test . >"$tmp/out" 2>&1)
if [ $? -eq 1 ]; then ok; else bad "a mistyped directive: not a failure"; fi
contains "a mistyped directive: named" "$tmp/out" "line 3: '# expcet:' is not a directive; did you mean '# expect:'?"
lacks "a comment with a colon is no directive" "$tmp/out" "line 4"

# on a terminal a progress line on standard error names the test that runs; on a pipe, nothing
mkdir -p "$tmp/progress" && printf 'derive 1;\naxiom: F;\n# expect: F\n' >"$tmp/progress/one.plant"
if command -v script >/dev/null 2>&1; then
  (cd "$tmp/progress" && script -qec "'$plant' test ." /dev/null) | tr '\r' '\n' >"$tmp/tty"
  contains "the progress line on a terminal" "$tmp/tty" "test 1/1: ./one.plant"
fi
(cd "$tmp/progress" && "$plant" test . 2>"$tmp/err" >/dev/null)
if [ ! -s "$tmp/err" ]; then ok; else bad "progress on a pipe: $(head -c 200 "$tmp/err")"; fi

echo "plant_test: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
