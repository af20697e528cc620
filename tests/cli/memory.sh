#!/usr/bin/env bash
# The memory budget (docs/language.md, "Limits"): --max-memory bounds the memory a command really
# takes, measured as the peak resident size of the child process (getrusage(RUSAGE_CHILDREN),
# through python3).
set -u
plant=$(realpath "${1:?usage: memory.sh PLANT}")
. "$(dirname "$0")/checks.sh"
# peak KB prints the child's peak resident size in KB; its exit code is the child's
peak() {
  python3 -c '
import resource, subprocess, sys
rc = subprocess.call(sys.argv[2:], stdout=open(sys.argv[1] + ".out", "w"), stderr=open(sys.argv[1] + ".err", "w"))
print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)
sys.exit(rc)' "$@"
}

# a string that doubles every step, with a parameter a module: 2^30 modules would take 16 GB
cat >"$tmp/grow.plant" <<'G'
axiom: A(1);
derive 30;
rules { A(x) -> A(x + 1) A(x * 2); }
G
cat >"$tmp/tiny.plant" <<'G'
axiom: A(1);
derive 2;
rules { A(x) -> A(x + 1); }
G
# the baseline: what plant takes deriving almost nothing (program, libraries, thread stacks)
base_kb=$(cd "$tmp" && peak "$tmp/p" "$plant" derive --threads 2 "$tmp/tiny.plant")
[ -n "$base_kb" ] && ok || bad "baseline: no peak measured"
for threads in 1 2; do
  kb=$(cd "$tmp" && peak "$tmp/p" "$plant" derive --threads $threads --max-memory 256M "$tmp/grow.plant")
  rc=$?
  [ $rc -eq 70 ] && ok || bad "--max-memory 256M, $threads threads: exit $rc, expected 70"
  contains "--max-memory 256M names the knob" "$tmp/p.err" "raise --max-memory"
  # 256 MB and the baseline, and 16 MB for the pages a freed string keeps (big_pages)
  limit_kb=$((256 * 1024 + base_kb + 16 * 1024))
  if [ "${kb:-999999999}" -le $limit_kb ]; then ok; else
    bad "--max-memory 256M, $threads threads: peak resident ${kb} KB, more than 256 MB + baseline $base_kb KB + 16 MB"
  fi
  echo "memory: $threads threads peaked at $((kb / 1024)) MB under --max-memory 256M (baseline $((base_kb / 1024)) MB)"
done
# run: the skeleton and each file's text are charged too (before the budget, a .skel.json of this
# tree peaked at 600 MB and an SVG at 320 MB under --max-memory 256M, as only the string was counted)
cat >"$tmp/tree.plant" <<'G'
axiom: A;
derive 19;
rules { A -> F[+A][-A]; }
G
for out in t.svg t.skel.json t.obj; do
  kb=$(cd "$tmp" && peak "$tmp/p" "$plant" run --max-memory 256M "$tmp/tree.plant" -o "$tmp/$out")
  rc=$?
  if [ $rc -eq 70 ]; then
    contains "run -o $out under 256M names the knob" "$tmp/p.err" "raise --max-memory"
    [ ! -e "$tmp/$out" ] && ok || bad "run -o $out: exit 70 but $out was written"
  else
    [ $rc -eq 0 ] && ok || bad "run -o $out under 256M: exit $rc, expected 0 or 70"
  fi
  limit_kb=$((256 * 1024 + base_kb + 16 * 1024))
  if [ "${kb:-999999999}" -le $limit_kb ]; then ok; else
    bad "run -o $out under --max-memory 256M: peak resident ${kb} KB, more than 256 MB + baseline $base_kb KB + 16 MB"
  fi
  echo "memory: run -o $out peaked at $((kb / 1024)) MB under --max-memory 256M (exit $rc)"
done
# repl: a step past the budget fails, and the session stays at the step before it
printf ':s 30\n:stats\n' >"$tmp/steps.repl"
check "repl under --max-memory 64M: the failing line" 1 "$plant" repl --max-memory 64M "$tmp/grow.plant" <"$tmp/steps.repl"
contains "repl under 64M names the knob" "$tmp/stderr" "the derivation needs more memory than --max-memory 64 MB allows"
contains "repl under 64M stays at the step before" "$tmp/stdout" "modules, "
# under a budget so small that copying the current step fails, the session survives too
for m in 8 16; do
  check "repl under --max-memory ${m}M: the failing line" 1 "$plant" repl --max-memory ${m}M "$tmp/grow.plant" <"$tmp/steps.repl"
  contains "repl under ${m}M names the knob" "$tmp/stderr" "needs more memory than --max-memory $m MB allows"
  contains "repl under ${m}M says where it stays" "$tmp/stderr" "still at step "
  contains "repl under ${m}M goes on to :stats" "$tmp/stdout" "modules, "
done
check "bad --max-memory is a usage error" 64 "$plant" derive --max-memory 12X "$tmp/tiny.plant"
contains "bad --max-memory" "$tmp/stderr" "--max-memory expects a size such as 512M or 4G, found '12X'"
check "check takes --max-memory" 0 "$plant" check --max-memory 64M "$tmp/tiny.plant"
# a size is digits and a unit, at least 1M: no empty value, no hexadecimal, exponent or sign
for bad in 1 1023K '' 0x10M 1e3M -1G 0.5M inf 12MB; do
  check "--max-memory '$bad' is a usage error" 64 "$plant" derive --max-memory "$bad" "$tmp/tiny.plant"
  contains "--max-memory '$bad' says what to write" "$tmp/stderr" "found '$bad': digits and the unit K, M or G, at least 1M"
done
for good in 1M 1024K 1.5G 2g 1048576; do
  check "--max-memory $good is a size" 0 "$plant" check --max-memory "$good" "$tmp/tiny.plant"
done

# with --seeds, --max-memory bounds the process: each of the --jobs J variants has a 1/J share
# (docs/batch.md). A 2^22-module string with a parameter (about 80 MB) fits the 128 MB its string
# may take on one job of 256M, not the 64 MB of a half share on two jobs. (256M rather than less:
# a sanitizer build's resident baseline alone is over 100 MB, and the resident-memory backstop
# allows the budget plus 96 MB.) The .svg output draws nothing (A is no turtle command).
cat >"$tmp/share.plant" <<'G'
derive 22;
axiom: A(22);
rules { A(n) : n > 0 -> A(n - 1) A(n - 1); }
G
check "one job has the whole --max-memory" 0 "$plant" run "$tmp/share.plant" --seeds 1..2 --jobs 1 \
  --max-memory 256M -o "$tmp/one_{seed}.svg"
check "two jobs have half of it each" 1 "$plant" run "$tmp/share.plant" --seeds 1..2 --jobs 2 \
  --max-memory 256M -o "$tmp/two_{seed}.svg"
contains "a variant's share is named" "$tmp/stderr" "more than the 64 MB it may take"
contains "and what to do" "$tmp/stderr" "with --jobs 2 each variant has a 1/2 share of --max-memory: lower --jobs or raise --max-memory"

echo "memory: $pass passed, $fail failed"
[ $fail -eq 0 ]
