#!/usr/bin/env bash
# plant test's children (docs/testing.md "Time limits and signals"): a test that runs past
# --timeout is stopped and fails; SIGTERM, SIGINT or SIGHUP to plant test stops its running child
# too, none left running (reparented to init).
set -u
plant=$(realpath "${1:?usage: plant_test_children.sh PLANT}")
. "$(dirname "$0")/checks.sh"

# a hook that never ends within the test's lifetime (10^14 loop turns, steps unbounded)
cat >"$tmp/forever.plant" <<'G'
# command: derive
# args: --max-steps 100000000000000000
# expect: F
var n = 0;
on start { for i in 0..1e7 { for j in 0..1e7 { n += 1; } } }
axiom: F;
G

start=$(date +%s)
check "a test past --timeout fails" 1 timeout -k 2 30 "$plant" test --timeout 1 "$tmp/forever.plant"
contains "the timeout is named" "$tmp/stdout" "did not end within 1 s: stopped (plant test --timeout SECONDS"
contains "counted as failed" "$tmp/stdout" "0 passed, 1 failed"
if [ $(($(date +%s) - start)) -le 8 ]; then ok; else bad "--timeout 1 took $(($(date +%s) - start)) s"; fi
check "--timeout must be a number of seconds" 64 "$plant" test --timeout 0 "$tmp/forever.plant"

set -m # background jobs of their own, which do not ignore SIGINT
for sig in TERM INT HUP; do
  "$plant" test "$tmp/forever.plant" >"$tmp/out" 2>&1 &
  parent=$!
  child=""
  for _ in $(seq 1 100); do
    child=$(pgrep -P "$parent" | head -n 1)
    [ -n "$child" ] && break
    sleep 0.05
  done
  if [ -n "$child" ]; then ok; else bad "SIG$sig: plant test started no child"; fi
  kill -s "$sig" "$parent"
  wait "$parent"
  rc=$?
  want=$((128 + $(kill -l "$sig")))
  if [ "$rc" -eq "$want" ]; then ok; else bad "SIG$sig: plant test ended with $rc, expected $want"; fi
  sleep 0.2
  if [ -n "$child" ] && ! kill -0 "$child" 2>/dev/null; then ok; else
    bad "SIG$sig: the child $child still runs after plant test ended"
    [ -n "$child" ] && kill -9 "$child"
  fi
done

echo "plant test children: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
