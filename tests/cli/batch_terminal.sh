#!/usr/bin/env bash
# A batch on a real terminal, driven through tmux (docs/batch.md): the progress bar with the
# rate and ETA while it runs, cleared at the end for the summary line; and Ctrl-C, which ends
# the batch with no partial or temporary file. A private tmux server (its own socket).
set -u
command -v tmux >/dev/null 2>&1 || { echo "batch_terminal: tmux not installed: skipped"; exit 77; }
plant=$(realpath "${1:?usage: batch_terminal.sh PLANT}")
rose=$(cd "$(dirname "$0")/../.." && pwd)/grammars/rose/fig12c.plant
tmp=$(mktemp -d)
sock=$tmp/tmux.sock
t() { tmux -S "$sock" "$@"; }
trap 't kill-server >/dev/null 2>&1; rm -rf "$tmp"' EXIT
pass=0
fail=0
ok() { pass=$((pass + 1)); }
bad() {
  fail=$((fail + 1))
  echo "FAIL $*"
  screen | grep -v '^\s*$' | tail -4 | sed 's/^/  /'
}
session=none
screen() { t capture-pane -p -J -S - -t "$session" 2>/dev/null; }
has() { screen | grep -q -F -- "$1"; }
poll() { # poll SECONDS COMMAND...
  local end=$((SECONDS + $1))
  shift
  until "$@"; do
    [ "$SECONDS" -ge "$end" ] && return 1
    sleep 0.05
  done
}
# run NAME SEEDS: a batch in a tmux session of its own, its exit status printed after it (the
# shell traps SIGINT, so it goes on to print the status after Ctrl-C; plant gets the default)
run() {
  session=$1
  t new-session -d -s "$session" -x 150 -y 20 -c "$tmp" \
    "bash -c \"trap 'echo INT' INT; '$plant' run '$rose' --seeds $2 -o '$1/rose-{seed}.glb' --manifest $1/m.jsonl; echo EXIT=\\\$?; sleep 60\""
}

# the bar while it runs, then the summary in its place
run done 1..120
poll 30 has "/120" && ok || bad "no progress bar"
# the rate and ETA appear once the first variant is done (slow under the sanitizers)
poll 60 has "ETA" && ok || bad "no ETA on the bar"
has "/s" && ok || bad "no rate on the bar"
poll 60 has "EXIT=0" && ok || bad "the batch did not end with 0"
has "plant: 120 of 120 variants in" && ok || bad "no summary line"
has "ETA" && bad "the bar was left on the screen" || ok
[ "$(ls "$tmp/done" | grep -c '\.glb$')" -eq 120 ] && ok || bad "not every rose written"

# Ctrl-C: the signal's exit status, whole files, no temporary file
run stopped 1..3000
poll 30 has "ETA" || bad "no progress bar before Ctrl-C"
t send-keys -t "$session" C-c
poll 20 has "EXIT=130" && ok || bad "Ctrl-C did not end it with 130"
has "(interrupted)" && ok || bad "no interrupted summary"
[ "$(ls -A "$tmp/stopped" | grep -c plant-tmp)" -eq 0 ] && ok || bad "temporary files left"
[ "$(ls "$tmp/stopped" | grep -c '\.glb$')" -eq "$(wc -l <"$tmp/stopped/m.jsonl")" ] && ok ||
  bad "the manifest does not list the files written"

echo "batch_terminal: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
