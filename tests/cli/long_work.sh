#!/usr/bin/env bash
# Long work (issue 20, item 13): the progress line of plant run on a terminal (steps, modules,
# rates, an estimate, meshing with its triangle estimate, writing), --max-triangles stopping
# before meshing, and derive --stats printing the steps it finished when a later one fails.
set -u
plant=$(realpath "${1:?usage: long_work.sh PLANT}")
src=$(cd "$(dirname "$0")/../.." && pwd)
. "$(dirname "$0")/checks.sh"
g=$src/grammars/abop/fig1_24a.plant

# on a terminal (script(1) gives the run one), the stages show
if command -v script >/dev/null 2>&1; then
  script -qec "'$plant' run '$g' -n 6 -o '$tmp/t.glb'" /dev/null | tr '\r' '\n' >"$tmp/tty"
  contains "step with a rate" "$tmp/tty" "step 6/6: 39 thousand modules, "
  lacks "no estimate while the string is small" "$tmp/tty" "s left"
  contains "interpreting" "$tmp/tty" "interpreting the string"
  contains "meshing with its estimate" "$tmp/tty" "meshing about "
  contains "writing" "$tmp/tty" "writing $tmp/t.glb (1 of 1)"
  contains "summary" "$tmp/tty" "39061 modules, "
  # an estimate once the string is large enough for its steps' times to follow it (195 thousand
  # modules at step 7), from the strings' growth: under a minute for a run of a second
  script -qec "'$plant' run '$g' -n 8 -o '$tmp/t.txt'" /dev/null | tr '\r' '\n' >"$tmp/tty"
  contains "an estimate of the time left" "$tmp/tty" "step 7/8: 195 thousand modules, "
  left=$(grep -ao 'about [0-9]* s left' "$tmp/tty" | head -1 | tr -dc 0-9)
  if [ -n "$left" ] && [ "$left" -lt 60 ]; then ok; else bad "the estimate: '$left' s left"; fi
else
  echo "long_work: script(1) not installed: the terminal part skipped"
fi
# not a terminal: quiet
"$plant" run "$g" -n 6 -o "$tmp/q.glb" 2>"$tmp/quiet"
if [ ! -s "$tmp/quiet" ]; then ok; else bad "progress on a pipe: $(head -c 200 "$tmp/quiet")"; fi

# --max-triangles: stops before meshing, with the estimate and what to do
"$plant" run "$g" -n 7 --max-triangles 100000 -o "$tmp/m.glb" 2>"$tmp/err"
got=$?
if [ "$got" -eq 70 ]; then ok; else bad "--max-triangles: exit $got, expected 70"; fi
contains "--max-triangles message" "$tmp/err" "meshing would make about 1.5 million triangles (78125 segments of 8 sides, 0 organs), more than --max-triangles 100 thousand allows"
contains "--max-triangles says what to do" "$tmp/err" "raise --max-triangles"
if [ ! -e "$tmp/m.glb" ]; then ok; else bad "an output after --max-triangles stopped the run"; fi
"$plant" run "$g" -n 7 --max-triangles 2e6 -o "$tmp/m.glb" 2>"$tmp/err"
if [ -s "$tmp/m.glb" ]; then ok; else bad "--max-triangles 2e6 stopped a run of 1.9 million"; fi
"$plant" run "$g" -n 7 --max-triangles 0 -o "$tmp/m.glb" 2>"$tmp/err"
if [ $? -eq 64 ]; then ok; else bad "--max-triangles 0 is not a usage error"; fi

# derive --stats: the steps that finished are printed when a later step fails
"$plant" derive "$g" -n 5 --max-modules 2000 --stats >"$tmp/stats" 2>"$tmp/err"
got=$?
if [ "$got" -eq 70 ]; then ok; else bad "--stats past the module limit: exit $got, expected 70"; fi
contains "finished steps" "$tmp/stats" "step 4 modules=1561 "
contains "where it failed" "$tmp/stats" "failed step=5 modules=1561 "
lacks "no total" "$tmp/stats" "total steps="
contains "the error" "$tmp/err" "step 5"

echo "long_work: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
