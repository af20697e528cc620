#!/usr/bin/env bash
# plant view without a browser (docs/view.md): usage, the server's routes and refusals with curl,
# a save seen through /api/state, Ctrl-C ending it cleanly, a port already taken.
#   tests/cli/view.sh PLANT
set -uo pipefail
plant="$1"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
. "$(dirname "${BASH_SOURCE[0]}")/checks.sh"
pids=()
trap 'for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done; rm -rf "$tmp"' EXIT

"$plant" view --help > "$tmp/help" 2>&1
holds "--help lists --port and --open" grep -q -- "--open" "$tmp/help"
"$plant" view "$tmp/missing.plant" --port 0 > /dev/null 2> "$tmp/err"; code=$?
holds "a missing grammar is exit 66" test "$code" = 66
holds "a missing grammar is named missing" grep -q "missing.plant': no such file" "$tmp/err"
mkdir -p "$tmp/adir"
"$plant" view "$tmp/adir" --port 0 > /dev/null 2> "$tmp/err"; code=$?
holds "a folder for the grammar is exit 66" test "$code" = 66
holds "a folder for the grammar is named a directory" grep -q "adir': it is a directory" "$tmp/err"

cp "$root/grammars/abop/fig1_24a.plant" "$tmp/g.plant"
mkdir "$tmp/scratch"
TMPDIR="$tmp/scratch" "$plant" view "$tmp/g.plant" --port 0 > "$tmp/out" 2>&1 &
pid=$!; pids+=("$pid")
for _ in $(seq 50); do grep -qs "http://" "$tmp/out" && break; sleep 0.1; done
url=$(grep -o 'http://127.0.0.1:[0-9]*/' "$tmp/out")
port=${url#http://127.0.0.1:}; port=${port%/}
holds "prints the URL on 127.0.0.1" test -n "$url"
status() { curl -s -o /dev/null -w '%{http_code}' "$@"; }
# eventually CMD...: whether CMD succeeds within 10 s (tried every 50 ms)
eventually() {
    for _ in $(seq 200); do "$@" && return 0; sleep 0.05; done
    return 1
}
state_has() { curl -s "${url}api/state" | grep -q "$@"; }
holds "serves the page" test "$(status "$url")" = 200
holds "the page loads its script" grep -q 'src="/viewer.js"' <(curl -s "$url")
holds "serves three.js" test "$(status "${url}three/three.module.js")" = 200
holds "serves the model as GLB" test "$(curl -s "${url}api/model.glb" | head -c 4)" = glTF
holds "a foreign Host is refused" test "$(status -H "Host: attacker.example:$port" "$url")" = 403
holds "a foreign Origin is refused" test "$(status -H "Origin: http://attacker.example" "${url}api/state")" = 403
holds "a path with .. is refused" test "$(status --path-as-is "${url}../../etc/passwd")" = 400
holds "an encoded .. is refused" test "$(status --path-as-is "${url}%2e%2e/%2e%2e/etc/passwd")" = 400
holds "a file system path is not served" test "$(status "${url}etc/passwd")" = 404
holds "only declared params may be set" test "$(status -X POST -d '{"params":{"nope":1}}' "${url}api/controls")" = 400
holds "a malformed request is refused" test "$(status -X POST -d 'run rm -rf /' "${url}api/controls")" = 400
holds "the seed must be digits" test "$(status -X POST -d '{"seed":"1;ls"}' "${url}api/controls")" = 400
holds "a huge request is refused" test "$(head -c 200000 /dev/zero | tr '\0' 'x' | curl -s -o /dev/null -w '%{http_code}' -X POST --data-binary @- "${url}api/controls")" = 413
v0=$(curl -s "${url}api/state" | grep -o '"version":[0-9]*')
m0=$(curl -s "${url}api/state" | grep -o '"modules":\[[0-9,]*\]')
sed -i 's/derive 5;/derive 3;/; s/^derive .*/derive 3;/' "$tmp/g.plant"
seen=""
for _ in $(seq 200); do
    m=$(curl -s "${url}api/state" | grep -o '"modules":\[[0-9,]*\]')
    [ "$m" != "$m0" ] && { seen=1; break; }
    sleep 0.05
done
holds "a save derives again (within 10 s here; the browser test holds it to 2 s) ($v0; $m0 -> $m)" test -n "$seen"
holds "the seed set on the page derives again" test "$(status -X POST -d '{"params":{},"seed":"7"}' "${url}api/controls")" = 200
# a param's range (`param n = 3 in 1 .. 8;`) reaches the page, and a value outside it is an error
printf 'param n = 3 in 1 .. 8;\naxiom: A(n);\nderive 4;\nrules { A(x) : x > 0 -> F A(x - 1); }\n' > "$tmp/g.plant"
holds "a param's range is in the state" eventually state_has '"high":8.0,"low":1.0,"name":"n"\|"low":1.0,"name":"n"'
holds "a value outside the range is accepted as a request" test "$(status -X POST -d '{"params":{"n":9}}' "${url}api/controls")" = 200
holds "and derives to an error naming the range" eventually state_has "outside its range 1 .. 8"
holds "an edit names an environment the grammar declares" grep -q "no environment 'ivy'" <(curl -s -X POST -d '{"step":1,"env":"ivy","method":"cut","args":[3]}' "${url}api/edit")
holds "an edit is a call, not source text" test "$(status -X POST -d '{"step":1,"call":"ivy.cut(3); system()"}' "${url}api/edit")" = 400
holds "undo without an edit is refused" test "$(status -X POST -d '{"undo":true}' "${url}api/edit")" = 400
holds "the export's scratch folder is under TMPDIR" test "$(ls "$tmp/scratch" | wc -l)" = 1
"$plant" view "$tmp/g.plant" --port "$port" > /dev/null 2> "$tmp/err2"; code=$?
holds "a port in use is exit 70 with advice" test "$code" = 70 -a -n "$(grep -- '--port 0' "$tmp/err2")"
kill -INT "$pid"
for _ in $(seq 40); do kill -0 "$pid" 2>/dev/null || break; sleep 0.05; done
wait "$pid"; code=$?
holds "Ctrl-C stops it cleanly (exit 0)" test "$code" = 0
holds "and removes its scratch folder" test "$(ls "$tmp/scratch" | wc -l)" = 0

# picking (/api/pick): a bonsai branch's segment names the branch's graph node, not the root's
"$plant" view "$root/grammars/bonsai/chokkan.plant" --port 0 > "$tmp/out2" 2>&1 &
pid=$!; pids+=("$pid")
for _ in $(seq 100); do grep -qs "http://" "$tmp/out2" && break; sleep 0.1; done
url=$(grep -o 'http://127.0.0.1:[0-9]*/' "$tmp/out2")
curl -s "${url}api/pick?kind=tube&x=0&y=0.1&z=0" > "$tmp/trunk.json"
holds "a click on the trunk is the root node" grep -q '"node":{"by":"axis","path":"/",' "$tmp/trunk.json"
curl -s "${url}api/pick?kind=tube&x=0.11&y=0.49&z=0.02" > "$tmp/branch.json"
holds "a click on a branch is the branch's node" grep -q '"node":{"by":"axis","path":"/0\.[0-9]*",' "$tmp/branch.json"
holds "a pick needs three finite numbers" test "$(status "${url}api/pick?x=nan&y=0&z=0")" = 400
holds "an organ pick needs its placement" test "$(status "${url}api/pick?kind=organ&x=0&y=0&z=0")" = 400
holds "a pick's kind is tube or organ" test "$(status "${url}api/pick?kind=file&x=0&y=0&z=0")" = 400
kill -INT "$pid"; wait "$pid"

# a climber edit at the last step derives one step more; a shorter grammar then is not lengthened
cat > "$tmp/cl.plant" <<'EOF2'
import climber with { N = 1, B = 1, BP = 0, V = 0.2, Ph = 0.5, shoot_length = 40, steps = 6 };
env ivy = climber(plane_point: vec3(0, 0, 0), plane_normal: vec3(0, 1, 0), anchor: 0.4, anchor_range: 0.03);
seed 12;
EOF2
"$plant" view "$tmp/cl.plant" --port 0 > "$tmp/out3" 2>&1 &
pid=$!; pids+=("$pid")
for _ in $(seq 100); do grep -qs "http://" "$tmp/out3" && break; sleep 0.1; done
url=$(grep -o 'http://127.0.0.1:[0-9]*/' "$tmp/out3")
steps_of() { curl -s "${url}api/state" | python3 -c 'import json, sys; print(len(json.load(sys.stdin)["modules"]) - 1)'; }
holds "the climber derives its 6 steps" test "$(steps_of)" = 6
curl -s -X POST -d '{"step":6,"env":"ivy","method":"wind","args":[[3, 0, 0]]}' "${url}api/edit" > "$tmp/edit.json"
holds "an edit at the last step derives one step more" grep -q '"command":"plant run [^"]* -n 7"' "$tmp/edit.json"
holds "a step past the last is refused" test "$(status -X POST -d '{"step":9,"env":"ivy","method":"cut","args":[3]}' "${url}api/edit")" = 400
holds "a fractional step is refused" test "$(status -X POST -d '{"step":2.5,"env":"ivy","method":"cut","args":[3]}' "${url}api/edit")" = 400
holds "args must be a list" test "$(status -X POST -d '{"step":2,"env":"ivy","method":"cut","args":{"a":3}}' "${url}api/edit")" = 400
sed -i 's/steps = 6/steps = 4/' "$tmp/cl.plant"
four_steps() { [ "$(steps_of)" = 4 ]; }
holds "a shorter grammar after it is not lengthened" eventually four_steps
kill -INT "$pid"; wait "$pid"
[ "$fail" -eq 0 ]
