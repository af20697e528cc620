#!/usr/bin/env bash
# Hostile inputs: each case must end within 10 s, under a 4 GB address-space limit, with the
# exit code and message it names. A case is a file tests/hostile/NAME.plant (or NAME.sh for
# cases that are not a grammar) with directives in comments:
#
#   # hostile: what a stranger's file tries (one line, for the report)
#   # setup: SHELL          run first, in a fresh scratch folder (the current directory);
#                           {case} is the case's own folder; may repeat
#   # run: ARGS             plant's arguments; {file} is the case, {dir} the scratch folder
#                           (default: check {file})
#   # exit: N               the exit code it must end with
#   # stderr: TEXT          a line of standard error must contain TEXT; may repeat
#   # stdout: TEXT          likewise for standard output
#   # absent: PATH          after the run, PATH (under {dir}) must not exist; may repeat
#
# usage: tests/hostile/run.sh PLANT [CASE...]
#
# For a sanitizer build (make test-sanitize, docs/testing.md): HOSTILE_NO_VM_LIMIT=1 drops the
# address-space limit, which AddressSanitizer's shadow memory cannot live under (its allocator
# limits, from ASAN_OPTIONS, stand in); HOSTILE_TIMEOUT=S gives each case S seconds instead of 10,
# for a build that runs several times slower. Without a limit, a case whose expected outcome is
# running out of address space ends in the sanitizer's allocator report instead: it is counted
# as skipped, not passed (the ordinary build runs it under the limit).
set -u
plant=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
shift
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
cases=("$@")
if [ ${#cases[@]} -eq 0 ]; then
  mapfile -t cases < <(find "$here" -maxdepth 1 -name '*.plant' -o -maxdepth 1 -name '*.case' | sort)
fi
limit_kb=$((4 * 1024 * 1024))
[ -n "${HOSTILE_NO_VM_LIMIT:-}" ] && limit_kb=unlimited
seconds=${HOSTILE_TIMEOUT:-10}
passed=0 failed=0 skipped=0
for c in "${cases[@]}"; do
  name=$(basename "$c")
  dir=$(mktemp -d)
  directive() { sed -n "s/^# $1: \{0,1\}//p" "$c"; }
  subst() { local s=${1//\{file\}/$c}; s=${s//\{dir\}/$dir}; printf '%s' "${s//\{case\}/$here}"; }
  ok=1 why=""
  while IFS= read -r line; do
    [ -z "$line" ] && continue
    (cd "$dir" && eval "$(subst "$line")") >/dev/null 2>&1 || { ok=0; why="setup failed: $line"; }
  done < <(directive setup)
  args=$(directive run | head -n 1)
  [ -z "$args" ] && args="check {file}"
  args=$(subst "$args")
  want_exit=$(directive exit | head -n 1)
  start=$(date +%s%N)
  if [ $ok -eq 1 ]; then
    (cd "$dir" && { [ "$limit_kb" = unlimited ] || ulimit -v $limit_kb; } && eval "exec timeout -k 2 $seconds \"\$plant\" $args") \
      >"$dir/.stdout" 2>"$dir/.stderr" </dev/null
    rc=$?
  else
    rc=-1
  fi
  ms=$(( ($(date +%s%N) - start) / 1000000 ))
  if [ $ok -eq 1 ] && { [ $rc -eq 124 ] || [ $rc -eq 137 ]; }; then ok=0; why="did not end within $seconds s"; fi
  if [ $ok -eq 1 ] && [ "$limit_kb" = unlimited ] && [ "$rc" != "$want_exit" ] \
    && grep -qE 'AddressSanitizer: (.*out of memory|requested allocation size|allocation-size-too-big|.*rss limit)' \
      "$dir/.stderr"; then
    skipped=$((skipped + 1))
    echo "SKIP $name: needs the address-space limit ($(grep -m1 -oE 'AddressSanitizer: [^(]*' "$dir/.stderr"))"
    rm -rf "$dir"
    continue
  fi
  if [ $ok -eq 1 ] && [ -n "$want_exit" ] && [ "$rc" != "$want_exit" ]; then
    ok=0; why="exit $rc, expected $want_exit"
  fi
  while IFS= read -r text; do
    [ -z "$text" ] && continue
    if [ $ok -eq 1 ] && ! grep -qF -- "$(subst "$text")" "$dir/.stderr"; then ok=0; why="stderr lacks: $text"; fi
  done < <(directive stderr)
  while IFS= read -r text; do
    [ -z "$text" ] && continue
    if [ $ok -eq 1 ] && ! grep -qF -- "$(subst "$text")" "$dir/.stdout"; then ok=0; why="stdout lacks: $text"; fi
  done < <(directive stdout)
  while IFS= read -r p; do
    [ -z "$p" ] && continue
    if [ $ok -eq 1 ] && [ -e "$dir/$p" ]; then ok=0; why="left $p behind"; fi
  done < <(directive absent)
  if [ $ok -eq 1 ]; then
    passed=$((passed + 1))
  else
    failed=$((failed + 1))
    echo "FAIL $name ($(directive hostile | head -n 1)): $why [${ms} ms]"
    head -c 600 "$dir/.stderr" | sed 's/^/  stderr: /'
  fi
  rm -rf "$dir"
done
echo "hostile: $passed passed, $failed failed$([ $skipped -gt 0 ] && echo ", $skipped skipped")"
[ $failed -eq 0 ] && [ $passed -gt 0 ]
