#!/usr/bin/env bash
# plant view's HTTP server is a module only `plant view` loads (docs/view.md, cli/view_http.hpp):
# the program itself links neither cpp-httplib nor the TLS and compression libraries Debian's
# build of it needs; the module beside it does, and exports only its entry point. A program
# without the module still checks and runs grammars, and `plant view` then fails at once, exit
# 66, naming where it looked; an unusable module is exit 70. The module in PREFIX/lib/plant/
# beside PREFIX/bin/plant serves.
#   tests/cli/view_module.sh PLANT
set -uo pipefail
plant="$1"
build=$(dirname "$plant")
module="$build/plant-view-server.so"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
. "$(dirname "${BASH_SOURCE[0]}")/checks.sh"
pids=()
trap 'for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done; rm -rf "$tmp"' EXIT
lacks() { ! grep -q "$@"; }

readelf -d "$plant" > "$tmp/needed" || fail=1
ldd "$plant" > "$tmp/ldd" || fail=1
for lib in libcpp-httplib libssl libcrypto libbrotli; do
    holds "plant does not link $lib" lacks "$lib" "$tmp/needed"
    holds "plant loads no $lib at start" lacks "$lib" "$tmp/ldd"
done
holds "the module is built beside plant" test -f "$module"
readelf -d "$module" > "$tmp/module-needed" || fail=1
holds "the module links cpp-httplib" grep -q 'NEEDED.*libcpp-httplib' "$tmp/module-needed"
nm -D --defined-only "$module" | awk '$2 ~ /^[TtWDBRV]$/ { print $3 }' > "$tmp/exports"
holds "the module exports its entry point" grep -qx 'plant_view_http_serve_v1' "$tmp/exports"
holds "and nothing else of its own ($(tr '\n' ' ' < "$tmp/exports"))" test "$(grep -vc -e '^_init$' -e '^_fini$' "$tmp/exports")" = 1

printf 'axiom: F;\nderive 1;\n' > "$tmp/g.plant"
# without the module: everything but view works; view fails before doing any work
mkdir -p "$tmp/alone/bin"
cp "$plant" "$tmp/alone/bin/"
holds "a plant without the module still checks" "$tmp/alone/bin/plant" check "$tmp/g.plant"
"$tmp/alone/bin/plant" view "$tmp/g.plant" --port 0 > "$tmp/out" 2> "$tmp/err"; code=$?
holds "view without the module is exit 66 (got $code)" test "$code" = 66
holds "it says the module is missing" grep -q "needs its HTTP server module, which is missing" "$tmp/err"
holds "naming the install's place" grep -qF "'$tmp/alone/lib/plant/plant-view-server.so'" "$tmp/err"
holds "and the program's folder" grep -qF "'$tmp/alone/bin/plant-view-server.so'" "$tmp/err"
holds "and serves nothing" test ! -s "$tmp/out"

# a file of that name that is not a loadable module, or a library without the entry point: 70
mkdir -p "$tmp/alone/lib/plant"
echo "not a library" > "$tmp/alone/lib/plant/plant-view-server.so"
"$tmp/alone/bin/plant" view "$tmp/g.plant" --port 0 > /dev/null 2> "$tmp/err"; code=$?
holds "an unloadable module is exit 70 (got $code)" test "$code" = 70
holds "it says why it cannot load it" grep -q "cannot load plant view's HTTP server module '$tmp/alone/lib/plant/plant-view-server.so'" "$tmp/err"
other=$(ldd "$plant" | awk '/libfmt/ { print $3 }')
cp "$other" "$tmp/alone/lib/plant/plant-view-server.so"
"$tmp/alone/bin/plant" view "$tmp/g.plant" --port 0 > /dev/null 2> "$tmp/err"; code=$?
holds "a library without the entry point is exit 70 (got $code)" test "$code" = 70
holds "it names the entry point" grep -q "it has no plant_view_http_serve_v1" "$tmp/err"

# the installed layout: PREFIX/bin/plant loads PREFIX/lib/plant/plant-view-server.so and serves
cp "$module" "$tmp/alone/lib/plant/plant-view-server.so"
"$tmp/alone/bin/plant" view "$tmp/g.plant" --port 0 > "$tmp/out" 2>&1 &
pid=$!; pids+=("$pid")
for _ in $(seq 100); do grep -qs "http://" "$tmp/out" && break; sleep 0.1; done
url=$(grep -o 'http://127.0.0.1:[0-9]*/' "$tmp/out")
holds "the installed layout serves" test -n "$url"
holds "the state" grep -q '"version"' <(curl -s "${url}api/state")
kill -INT "$pid"
wait "$pid"; code=$?
holds "and stops cleanly" test "$code" = 0
[ "$fail" -eq 0 ]
