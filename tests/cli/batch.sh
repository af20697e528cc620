#!/usr/bin/env bash
# plant run with many variants (docs/batch.md): the same files and manifest rows on 1 and 2 jobs,
# failing variants as manifest rows, --shard slices, --grid products, usage errors and an
# interrupted batch that leaves no partial file.
set -u
plant=$(realpath "${1:?usage: batch.sh PLANT}")
here=$(cd "$(dirname "$0")" && pwd)
bush=$here/batch/bush.plant
unlucky=$here/batch/unlucky.plant
. "$here/checks.sh"
cd "$tmp" || exit 1
same() { # same NAME FILE1 FILE2
  if cmp -s "$2" "$3"; then ok; else
    bad "$1: $2 and $3 differ"
    diff "$2" "$3" | head -6
  fi
}
equal() { # equal NAME GOT WANT
  if [ "$2" = "$3" ]; then ok; else bad "$1: got '$2', expected '$3'"; fi
}
untimed() { sed 's/"ms":[0-9.]*,//' "$1"; } # a JSON-lines manifest without the times

# --- 1 and 2 jobs: the same files, byte for byte, and the same rows -------------------------------
check "seeds on 1 job" 0 "$plant" run "$bush" --seeds 1..64 --jobs 1 -o 'j1/bush-{seed}.glb' \
  -o 'j1/bush-{seed}.txt' --manifest j1/manifest.jsonl
check "seeds on 2 jobs" 0 "$plant" run "$bush" --seeds 1..64 --jobs 2 -o 'j2/bush-{seed}.glb' \
  -o 'j2/bush-{seed}.txt' --manifest j2/manifest.jsonl
equal "64 GLBs" "$(ls j2/*.glb | wc -l)" 64
for f in j1/*.glb j1/*.txt; do
  cmp -s "$f" "j2/${f#j1/}" && ok || bad "jobs: $f differs on 2 jobs"
done
untimed j1/manifest.jsonl | sed 's#j1/#DIR/#g' >rows1
untimed j2/manifest.jsonl | sed 's#j2/#DIR/#g' >rows2
same "manifest rows on 1 and 2 jobs" rows1 rows2
equal "a row per variant" "$(wc -l <rows1)" 64
contains "row 0" rows1 '{"n":0,"seed":1,"params":{},"outputs":["DIR/bush-1.glb","DIR/bush-1.txt"],"modules":'
contains "row 63" rows1 '{"n":63,"seed":64,'
# the seeds give different plants, and a variant is the single run with that seed
if cmp -s j1/bush-1.glb j1/bush-2.glb; then bad "seeds 1 and 2 give the same plant"; else ok; fi
check "single run" 0 "$plant" run "$bush" --seed 17 -o single.glb
same "variant = single run" single.glb j2/bush-17.glb

# environments (a climber's physics, its obstacles) belong to each variant's derivation
boxes=$here/../../grammars/climbers/fig09_boxes.plant
for jobs in 1 2; do
  check "climber on $jobs jobs" 0 "$plant" run "$boxes" --seeds 1..6 --jobs "$jobs" -o "c$jobs/{seed}.glb"
done
for f in c1/*.glb; do cmp -s "$f" "c2/${f#c1/}" && ok || bad "climber: $f differs on 2 jobs"; done
check "climber single run" 0 "$plant" run "$boxes" --seed 4 -o climber.glb
same "climber variant = single run" climber.glb c2/4.glb

# --- failing variants: a manifest row each, the others written, exit 1 ---------------------------
check "failing variants" 1 "$plant" run "$unlucky" --seeds 1..64 -o 'u/u-{seed}.glb' --manifest u/m.csv
failed=$(grep -c ',runtime_error,' u/m.csv)
written=$(ls u/*.glb | wc -l)
[ "$failed" -gt 0 ] && [ "$failed" -lt 64 ] && ok || bad "unlucky: $failed of 64 failed"
equal "failed + written" $((failed + written)) 64
contains "csv header" u/m.csv "n,seed,outputs,modules,triangles,ms,status,message"
contains "failing row's message" u/m.csv "unlucky.plant:8:10: error: step 1: division by zero"
contains "failure on stderr" stderr "error: step 1: division by zero"
contains "summary on stderr" stderr "of 64 variants"
while IFS=, read -r n seed outputs rest; do
  case $rest in
  *,ok,) [ -f "u/u-$seed.glb" ] && [ "$outputs" = "u/u-$seed.glb" ] && ok || bad "ok row $n has no file" ;;
  *runtime_error*) [ ! -e "u/u-$seed.glb" ] && [ -z "$outputs" ] && ok || bad "failed row $n wrote a file" ;;
  esac
done < <(tail -n +2 u/m.csv)

# a file that cannot be written is an output_error row; commas and quotes survive CSV and JSON
touch blocker
check "output error" 1 "$plant" run "$bush" --seeds 1..2 -o 'blocker/{n}.txt' --manifest oe.jsonl
contains "output_error row" oe.jsonl '"status":"output_error","message":"cannot write '"'"'blocker/0.txt'"'"': cannot create a file in'
check "odd names" 0 "$plant" run "$bush" --seeds 1..2 -o 'odd/we"ird,{n}.txt' --manifest odd.csv
check "odd names, json" 0 "$plant" run "$bush" --seeds 1..2 -o 'odd/we"ird,{n}.txt' --manifest odd.jsonl
python3 - <<'PY' && ok || bad "CSV or JSON quoting"
import csv, json
rows = list(csv.DictReader(open("odd.csv")))
assert [r["outputs"] for r in rows] == ['odd/we"ird,0.txt', 'odd/we"ird,1.txt'], rows
assert [json.loads(l)["outputs"] for l in open("odd.jsonl")] == [['odd/we"ird,0.txt'], ['odd/we"ird,1.txt']]
PY

# --- --shard: every variant in exactly one slice; the slices' rows make the whole manifest -------
check "whole" 0 "$plant" run "$bush" --seeds 1..64 -o 'w/{n}.txt' --manifest whole.jsonl
for N in 1 3 7; do
  : >"merged$N"
  for K in $(seq 1 "$N"); do
    check "shard $K/$N" 0 "$plant" run "$bush" --seeds 1..64 --shard "$K/$N" -o "s$N/{n}.txt" \
      --manifest "s$N/m$K.jsonl"
    cat "s$N/m$K.jsonl" >>"merged$N"
    # shard K holds the variants n with n mod N = K - 1
    others=$(grep -o '^{"n":[0-9]*' "s$N/m$K.jsonl" | cut -d: -f2 | awk -v N="$N" -v K="$K" '$1 % N != K - 1')
    equal "shard $K/$N holds its slice" "$others" ""
  done
  equal "N=$N: each variant once" "$(grep -o '^{"n":[0-9]*' "merged$N" | cut -d: -f2 | sort -n | uniq | tr '\n' ' ')" \
    "$(seq 0 63 | tr '\n' ' ')"
  equal "N=$N: 64 rows" "$(wc -l <"merged$N")" 64
  sort -t: -k2,2n "merged$N" | untimed /dev/stdin | sed "s#s$N/#w/#g" >"sorted$N"
  untimed whole.jsonl >whole.rows
  same "N=$N: sorted shard rows = the whole manifest" "sorted$N" whole.rows
  for f in w/*.txt; do cmp -s "$f" "s$N/${f#w/}" || bad "N=$N: $f differs"; done
done
check "shard past the variants" 0 "$plant" run "$bush" --seeds 1..2 --shard 5/7 -o 'e/{n}.txt' --manifest e/m.jsonl
equal "an empty shard" "$(wc -c <e/m.jsonl)" 0

# --- --grid: the cartesian product with the seeds -------------------------------------------------
check "grid" 0 "$plant" run "$bush" --grid spread=10:30:10 --grid lean=0,5 --seeds 1..4 \
  -o 'g/{spread}-{lean}-{seed}.txt' --manifest g/m.jsonl
equal "grid rows" "$(wc -l <g/m.jsonl)" 24
equal "grid files" "$(ls g/*.txt | wc -l)" 24
contains "grid row: first --grid outermost, seeds inside" g/m.jsonl '{"n":9,"seed":2,"params":{"spread":20,"lean":0},"outputs":["g/20-0-2.txt"]'
check "grid value = -D" 0 "$plant" run "$bush" -D spread=20 -D lean=5 --seed 3 -o grid-single.txt
same "grid variant = the run with -D" grid-single.txt g/20-5-3.txt
check "grid with decimals" 0 "$plant" run "$bush" --grid spread=0.5:0.9:0.1 -o 'd/{spread}.txt'
equal "0.5:0.9:0.1 has five values" "$(ls d | tr '\n' ' ')" "0.5.txt 0.6.txt 0.7.txt 0.8.txt 0.9.txt "
check "grid only: one variant a value" 0 "$plant" run "$bush" --grid lean=1,2,3 -o 'l/{n}.txt' --manifest l/m.csv
equal "csv params column" "$(cut -d, -f3 l/m.csv | tr '\n' ' ')" "lean 1 2 3 "

# --- usage errors (exit 64) and nothing written ---------------------------------------------------
usage() { # usage NAME MESSAGE ARGS...
  local name=$1 message=$2
  shift 2
  check "$name" 64 "$plant" run "$bush" "$@"
  contains "$name says why" stderr "$message"
}
usage "seeds backwards" "--seeds expects A..B" --seeds 5..2 -o 'x/{seed}.glb'
usage "seeds not numbers" "--seeds expects A..B" --seeds a..b -o 'x/{seed}.glb'
usage "seeds negative" "--seeds expects A..B" --seeds -1..3 -o 'x/{seed}.glb'
usage "seeds too many" "more than 1000000000" --seeds 0..18446744073709551615 -o 'x/{seed}.glb'
usage "grid step 0" "--grid expects" --grid spread=1:2:0 -o 'x/{n}.glb'
usage "grid wrong way" "--grid expects" --grid spread=2:1:1 -o 'x/{n}.glb'
usage "grid no name" "--grid expects" --grid =1:2:1 -o 'x/{n}.glb'
usage "grid not a number" "is not a finite number" --grid spread=1,x -o 'x/{n}.glb'
usage "grid twice" "twice" --grid spread=1,2 --grid spread=3,4 -o 'x/{n}.glb'
usage "grid and -D" "set by -D and swept by --grid" -D spread=3 --grid spread=1,2 -o 'x/{n}.glb'
usage "grid too big" "more than 1000000000 variants" --grid spread=0:999999:1 --grid lean=0:9999:1 -o 'x/{n}.glb'
usage "shard 0" "--shard expects K/N" --seeds 1..3 --shard 0/3 -o 'x/{n}.glb'
usage "shard past N" "--shard expects K/N" --seeds 1..3 --shard 4/3 -o 'x/{n}.glb'
usage "shard N 0" "--shard expects K/N" --seeds 1..3 --shard 1/0 -o 'x/{n}.glb'
usage "shard no slash" "--shard expects K/N" --seeds 1..3 --shard 2 -o 'x/{n}.glb'
usage "no placeholder" "would be the same file" --seeds 1..3 -o x/bush.glb
usage "seed placeholder, grid" "put {n} (the variant's number) or {spread}" --seeds 1..3 --grid spread=1,2 -o 'x/{seed}.glb'
usage "unknown placeholder" "unknown placeholder {sede}" --seeds 1..3 -o 'x/{sede}.glb'
usage "output twice" "given twice" --seeds 1..3 -o 'x/{n}.glb' -o 'x/{n}.glb'
usage "seed and seeds" "--seed and --seeds" --seed 4 --seeds 1..3 -o 'x/{n}.glb'
usage "outputs differing only in placeholders" "differ only in their placeholders" --seeds 1..3 -o 'x/a-{seed}.txt' -o 'x/a-{n}.txt'
cp "$bush" bush_copy.csv
check "manifest over the grammar" 64 "$plant" run bush_copy.csv --seeds 1..2 -o 'x/{n}.txt' --manifest bush_copy.csv
contains "manifest over the grammar: why" stderr "is the grammar being run"
same "manifest over the grammar: the grammar kept" "$bush" bush_copy.csv
usage "manifest extension" "name a .jsonl" --seeds 1..3 -o 'x/{n}.glb' --manifest x/m.txt
usage "jobs alone" "give --seeds or --grid" --jobs 2 -o x/a.glb
usage "jobs 0" "--jobs" --seeds 1..3 --jobs 0 -o 'x/{n}.glb'
[ ! -e x ] && ok || bad "a usage error wrote files"
check "one variant needs no placeholder" 0 "$plant" run "$bush" --seeds 7..7 -o one.glb
check "grammar error stops the batch" 65 "$plant" run "$bush" --grid nosuch=1,2 -o 'x/{nosuch}.glb'
contains "grammar error says which" stderr "no param 'nosuch'"
check "default output" 0 "$plant" run "$bush" --seeds 1..2
[ -f out/bush-0.glb ] && [ -f out/bush-1.glb ] && ok || bad "default outputs out/bush-{n}.glb missing"

# --- interrupted: SIGTERM leaves whole files and no temporary file -------------------------------
"$plant" run "$here/../../grammars/rose/fig12c.plant" --seeds 1..2000 -o 'r/rose-{seed}.glb' \
  --manifest r/m.jsonl 2>/dev/null &
pid=$!
for _ in $(seq 100); do [ "$(ls r 2>/dev/null | grep -c glb)" -ge 3 ] && break; sleep 0.05; done
kill -TERM $pid
wait $pid
equal "ended by SIGTERM" $? 143
equal "no temporary file" "$(ls -A r | grep -c plant-tmp)" 0
done_rows=$(wc -l <r/m.jsonl)
[ "$done_rows" -ge 3 ] && [ "$done_rows" -lt 2000 ] && ok || bad "interrupted manifest has $done_rows rows"
equal "the manifest lists the files there" "$(ls r | grep -c glb)" "$done_rows"
seed=$(grep -o '"seed":[0-9]*' r/m.jsonl | tail -1 | cut -d: -f2)
check "reference rose" 0 "$plant" run "$here/../../grammars/rose/fig12c.plant" --seed "$seed" -o ref.glb
same "the last rose written is whole" ref.glb "r/rose-$seed.glb"

# a SIGINT ignored when plant starts (a background job of a script) stays ignored
bash -c "trap '' INT; exec '$plant' run '$here/../../grammars/rose/fig12c.plant' --seeds 1..40 \
  -o 'i/rose-{seed}.glb'" 2>/dev/null &
pid=$!
for _ in $(seq 100); do [ "$(ls i 2>/dev/null | grep -c glb)" -ge 2 ] && break; sleep 0.05; done
kill -INT $pid
wait $pid
equal "ignored SIGINT: the batch goes on" $? 0
equal "ignored SIGINT: every rose" "$(ls i | grep -c glb)" 40

echo "batch: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
