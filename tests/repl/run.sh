#!/usr/bin/env bash
# Transcript tests for `plant repl`: each NAME.in is fed to the REPL on standard input and the
# merged output (stdout and stderr) is compared with NAME.out.
#
#   tests/repl/run.sh [--bless] PLANT      (--bless rewrites the .out files from the output)
#
# NAME.in format:
#   - an optional first line `# file: PATH` (relative to tests/repl) gives the grammar to start
#     with: `plant repl PATH`; without it the REPL starts with no grammar. The line is also sent
#     to the REPL, which skips comment lines.
#   - a line starting with `!` is not sent to the REPL: the rest of the line is run by bash in
#     the working directory, between the previous command and the next one (to edit a grammar
#     before `:reload`, or to look at an exported file). Its output goes into the transcript.
#   - an optional line `# args: ARG...` gives plant repl more arguments (--max-modules 100).
#   - every other line is sent to the REPL as typed.
#
# Every transcript runs in its own temporary copy of tests/repl, so `!` edits, :export and
# :render never touch the repository. Timings ("0.012 ms") are normalized to "N ms".
#
# How `!` lines are ordered: a transcript without them is simply redirected to the REPL's
# standard input. With them, the lines are written one at a time to a FIFO. Before a `!` line
# the runner writes the marker line `:__sync__` (an unknown command) and waits until the REPL
# has answered it (its error names ':__sync__'); the REPL handles its lines in order and flushes
# both streams after each, so at that point every earlier line has been fully handled and the
# REPL is waiting for input. Only then is the shell command run; the marker's line is removed
# from the transcript. (A fixed `sleep` would be racy: the REPL may be slow to start or to
# derive.) Lines after the `!` line are written only once the command has finished, so a
# `:reload` that follows always sees the edit, even though the REPL may read ahead.
set -u
bless=0
if [ "${1:-}" = --bless ]; then
  bless=1
  shift
fi
plant=$(realpath "${1:?usage: run.sh [--bless] PLANT}")
here=$(cd "$(dirname "$0")" && pwd)
export NO_COLOR=1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
trap '' PIPE # a REPL that ended early (:quit) must not kill the runner when it writes more lines
limit=60      # seconds for one transcript
marker=':__sync__'
pass=0
fail=0

# run_fifo IN WORK RAW ARGS...: feed IN line by line, running `!` lines between commands
run_fifo() {
  local in=$1 work=$2 raw=$3
  shift 3
  local fifo=$tmp/fifo.$$.$RANDOM
  mkfifo "$fifo"
  (cd "$work" && exec timeout "$limit" "$plant" "$@" <"$fifo" >>"$raw" 2>&1) &
  local pid=$! fd line syncs=0 waited
  exec {fd}>"$fifo"
  while IFS= read -r line || [ -n "$line" ]; do
    if [[ $line == '!'* ]]; then
      syncs=$((syncs + 1))
      printf '%s\n' "$marker" >&"$fd" 2>/dev/null
      waited=0
      while [ "$(grep -c -F "'$marker'" "$raw")" -lt "$syncs" ] && kill -0 "$pid" 2>/dev/null &&
        [ "$waited" -lt $((limit * 100)) ]; do
        sleep 0.01
        waited=$((waited + 1))
      done
      (cd "$work" && bash -c "${line:1}") </dev/null >>"$raw" 2>&1
    else
      printf '%s\n' "$line" >&"$fd" 2>/dev/null
    fi
  done <"$in"
  exec {fd}>&-
  wait "$pid"
  rm -f "$fifo"
}

for in in "$here"/*.in; do
  [ -e "$in" ] || continue
  name=$(basename "$in" .in)
  expected=$here/$name.out
  work=$tmp/$name
  raw=$tmp/$name.raw
  got=$tmp/$name.got
  mkdir -p "$work"
  for f in "$here"/*; do
    case $f in *.in | *.out | *.sh) ;; *) cp -r "$f" "$work/" ;; esac
  done
  args=(repl)
  file=$(sed -n '1s/^# file: *//p' "$in")
  [ -n "$file" ] && args+=("$file")
  # an optional `# args: ...` line: more arguments for plant repl (split on spaces)
  read -r -a extra <<<"$(sed -n 's/^# args: *//p' "$in" | head -1)"
  args+=("${extra[@]}")
  : >"$raw"
  if grep -q '^!' "$in"; then
    run_fifo "$in" "$work" "$raw" "${args[@]}"
  else
    (cd "$work" && timeout "$limit" "$plant" "${args[@]}" <"$in" >>"$raw" 2>&1)
  fi
  grep -v -F "'$marker'" "$raw" | sed -E 's/[0-9]+(\.[0-9]+)? ms/N ms/g' >"$got"
  if [ "$bless" -eq 1 ]; then
    cp "$got" "$expected"
    echo "blessed $name"
    pass=$((pass + 1))
  elif [ -f "$expected" ] && cmp -s "$expected" "$got"; then
    pass=$((pass + 1))
  else
    fail=$((fail + 1))
    echo "FAIL $name"
    if [ -f "$expected" ]; then
      diff -u --label "$name.out (expected)" --label "$name (got)" "$expected" "$got"
    else
      echo "  $name.out is missing; the output was:"
      sed 's/^/  /' "$got"
    fi
  fi
done
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ] && [ "$pass" -gt 0 ] # running nothing is a failure too
