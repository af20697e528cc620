#!/usr/bin/env bash
# Beyond one process (docs/batch.md): GNU parallel runs three --shard slices of a batch at once;
# their files are the single run's, and their manifests, concatenated and sorted by n, are its
# manifest. Skipped (exit 77) without GNU parallel (Debian package parallel; scripts/install-deps).
set -u
plant=$(realpath "${1:?usage: batch_parallel.sh PLANT}")
bush=$(cd "$(dirname "$0")" && pwd)/batch/bush.plant
command -v parallel >/dev/null || { echo "batch_parallel: GNU parallel is not installed: skipped"; exit 77; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
fail=0
bad() {
  fail=$((fail + 1))
  echo "FAIL $*"
}

"$plant" run "$bush" --seeds 1..64 --grid lean=0,10 -o 'one/bush-{lean}-{seed}.glb' \
  --manifest one/manifest.jsonl 2>/dev/null || bad "the single run failed"
# {} is parallel's: the slice number; {lean} and {seed} are plant's placeholders
parallel --will-cite --halt now,fail=1 -j 3 "$plant" run "$bush" --seeds 1..64 --grid lean=0,10 \
  --shard {}/3 -o "'many/bush-{lean}-{seed}.glb'" --manifest "many/manifest-{}.jsonl" ::: 1 2 3 \
  2>/dev/null || bad "parallel: a shard failed"

[ "$(ls one/*.glb | wc -l)" -eq 128 ] || bad "the single run wrote $(ls one/*.glb | wc -l) files, not 128"
for f in one/*.glb; do cmp -s "$f" "many/${f#one/}" || bad "$f differs from the shards' file"; done
# the merge, as docs/batch.md gives it: rows sorted by n (the number after the first ':')
cat many/manifest-*.jsonl | sort -t: -k2,2n | sed 's/"ms":[0-9.]*,//; s#many/#one/#g' >merged
sed 's/"ms":[0-9.]*,//' one/manifest.jsonl >whole
cmp -s merged whole || { bad "the merged manifest is not the single run's"; diff merged whole | head -5; }
[ "$(wc -l <merged)" -eq 128 ] || bad "the merged manifest has $(wc -l <merged) rows"

echo "batch_parallel: $((fail == 0 ? 1 : 0)) passed, $fail failed"
[ "$fail" -eq 0 ]
