#!/usr/bin/env bash
# The libraries every plant process loads at start (docs/architecture.md, the command line):
# libedit, and the libtinfo, libbsd and libmd it brings, are loaded only by an interactive
# `plant repl` (dlopen; tests/repl/interactive.sh drives that one in tmux), and cpp-httplib with
# its TLS and compression libraries only by `plant view` (tests/cli/view_module.sh).
#   tests/cli/startup_libs.sh PLANT
set -uo pipefail
plant="$1"
fail=0
needed=$(readelf -d "$plant") || exit 1
loaded=$(ldd "$plant") || exit 1
for lib in libedit libtinfo libbsd libmd libcpp-httplib libssl libcrypto libbrotli libz; do
    if grep -q "$lib" <<<"$needed$loaded"; then echo "not ok - plant loads $lib at start"; fail=1
    else echo "ok - plant does not load $lib at start"; fi
done
# a REPL script (standard input not a terminal) runs without libedit
out=$(printf 'axiom: F;\n:step\n:quit\n' | "$plant" repl 2>&1); code=$?
if [ "$code" = 0 ]; then echo "ok - a REPL script runs"; else echo "not ok - a REPL script: exit $code: $out"; fail=1; fi
exit $fail
