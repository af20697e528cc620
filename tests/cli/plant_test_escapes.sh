#!/usr/bin/env bash
# plant test's report shows control characters from a test as escapes (\x1b), as every other
# message does: in file names, `# expect` lines, golden files and the output compared with them.
set -u
plant=$(realpath "${1:?usage: plant_test_escapes.sh PLANT}")
. "$(dirname "$0")/checks.sh"
esc=$'\x1b'

mkdir "$tmp/t"
printf '# expect: G%s[2J\naxiom: F;\n' "$esc" >"$tmp/t/expect_line.plant"
printf '# command: check\n# expect error: %s[2Jzz\naxiom: F;\n' "$esc" >"$tmp/t/expect_error.plant"
printf 'derive 1;\naxiom: F;\n' >"$tmp/t/golden.plant"
printf 'G%s[2J\n' "$esc" >"$tmp/t/golden.txt"
printf 'derive 1;\naxiom: F;\n' >"$tmp/t/name${esc}[2J.plant"
printf 'derive 1;\naxiom: F;\n' >"$tmp/t/mesh.plant"
printf 'F\n' >"$tmp/t/mesh.txt"
printf 'x%s[2J\n' "$esc" >"$tmp/t/mesh.mesh.txt"

check "the tests fail" 1 "$plant" test -v "$tmp/t"
if ! grep -q "$esc" "$tmp/stdout"; then ok; else
  bad "a raw escape character in plant test's report"
  grep -n "$esc" "$tmp/stdout" | cat -v | head -5
fi
contains "an expect line, escaped" "$tmp/stdout" 'expected: G\x1b[2J'
contains "an expected error, escaped" "$tmp/stdout" 'expected: \x1b[2Jzz'
contains "a golden file, escaped" "$tmp/stdout" 'expected: ...G\x1b[2J'
contains "a file name, escaped" "$tmp/stdout" 'name\x1b[2J.plant'
contains "a mesh summary, escaped" "$tmp/stdout" 'expected: ...x\x1b[2J'

# a golden file, or a test found in a folder, that is a symbolic link out of the test's folder is
# not read: a failing test would print an excerpt of it
mkdir -p "$tmp/links/in" && printf 'secret-token\n' >"$tmp/links/secret"
printf 'axiom: F;\n' >"$tmp/links/in/t.plant" && ln -s "$tmp/links/secret" "$tmp/links/in/t.txt"
printf 'axiom: F;\n' >"$tmp/links/in/m.plant" && printf 'F\n' >"$tmp/links/in/m.txt"
ln -s "$tmp/links/secret" "$tmp/links/in/m.mesh.txt"
ln -s "$tmp/links/secret" "$tmp/links/in/linked.plant"
printf 'axiom: F;\n' >"$tmp/links/in/ok.plant" && printf 'F\n' >"$tmp/links/in/ok.txt"
ln -s ok.txt "$tmp/links/in/inside.txt" && printf 'axiom: F;\n' >"$tmp/links/in/inside.plant"
check "links out of the folder fail" 1 "$plant" test -v "$tmp/links/in"
if grep -q secret-token "$tmp/stdout"; then bad "a linked file's contents were printed"; else ok; fi
contains "the golden file named" "$tmp/stdout" "in/t.txt is a symbolic link out of the test's folder"
contains "the mesh summary named" "$tmp/stdout" "in/m.mesh.txt is a symbolic link out of the test's folder"
contains "the linked test named" "$tmp/stdout" "in/linked.plant is a symbolic link out of the test's folder"
contains "a link inside the folder is read" "$tmp/stdout" "ok $tmp/links/in/inside.plant"
check "bless does not read them either" 1 "$plant" test --bless "$tmp/links/in"
if grep -q secret-token "$tmp/stdout"; then bad "bless printed a linked file's contents"; else ok; fi

echo "plant test escapes: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
