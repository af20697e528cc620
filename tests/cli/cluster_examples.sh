#!/usr/bin/env bash
# The job files of examples/cluster (docs/batch.md), run here without a cluster: the Slurm
# array script as each array task would run it (its SLURM_* variables set by hand, for arrays
# 1-3 and 0-2), merge-manifests on their manifests, and the Kubernetes Indexed Job's command as
# each pod would run it (JOB_COMPLETION_INDEX 0..2). Every way gives the files and the manifest
# of one plain run. The Job's fields are checked too, and its grammar compiles.
set -u
plant=$(realpath "${1:?usage: cluster_examples.sh PLANT}")
here=$(cd "$(dirname "$0")" && pwd)
cluster=$here/../../examples/cluster
bush=$here/batch/bush.plant
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
pass=0
fail=0
ok() { pass=$((pass + 1)); }
bad() {
  fail=$((fail + 1))
  echo "FAIL $*"
}
untimed() { sed 's/"ms":[0-9.]*,//' "$1"; }
same_run() { # same_run NAME DIR MANIFEST: DIR's files and MANIFEST are the plain run's
  local name=$1 dir=$2 manifest=$3 f
  [ "$(ls "$dir"/*.glb 2>/dev/null | wc -l)" -eq 30 ] && ok || bad "$name: $(ls "$dir"/*.glb 2>/dev/null | wc -l) GLBs, not 30"
  for f in whole/*.glb; do cmp -s "$f" "$dir/${f#whole/}" || bad "$name: $f differs"; done
  if cmp -s <(untimed whole/manifest.jsonl) <(untimed "$manifest" | sed "s#$dir/#whole/#g"); then ok; else
    bad "$name: the merged manifest is not the plain run's"
    diff <(untimed whole/manifest.jsonl) <(untimed "$manifest" | sed "s#$dir/#whole/#g") | head -4
  fi
}

"$plant" run "$bush" --seeds 1..30 -o 'whole/rose-{n}.glb' --manifest whole/manifest.jsonl 2>/dev/null ||
  bad "the plain run failed"

# --- Slurm: three array tasks, numbered from 1 and from 0 -----------------------------------------
for min in 1 0; do
  for id in $(seq "$min" $((min + 2))); do
    SLURM_ARRAY_TASK_ID=$id SLURM_ARRAY_TASK_MIN=$min SLURM_ARRAY_TASK_COUNT=3 SLURM_CPUS_PER_TASK=2 \
      PLANT=$plant GRAMMAR=$bush SEEDS=1..30 OUT=slurm$min bash "$cluster/roses.sbatch" 2>/dev/null ||
      bad "slurm task $id (array from $min) failed"
  done
  "$cluster/merge-manifests" "slurm$min/manifest.jsonl" slurm"$min"/manifest-*.jsonl || bad "merge-manifests failed"
  same_run "slurm array from $min" "slurm$min" "slurm$min/manifest.jsonl"
done
# merge-manifests on CSV: one header, rows by n
for k in 1 2; do "$plant" run "$bush" --seeds 1..5 --shard "$k/2" -o "csv/{n}.txt" --manifest "csv/m$k.csv" 2>/dev/null; done
"$plant" run "$bush" --seeds 1..5 -o "csv/{n}.txt" --manifest csv/whole.csv 2>/dev/null
"$cluster/merge-manifests" csv/merged.csv csv/m1.csv csv/m2.csv
if cmp -s <(cut -d, -f1-5 csv/whole.csv) <(cut -d, -f1-5 csv/merged.csv); then ok; else bad "merged CSV"; fi
"$cluster/merge-manifests" csv/merged.txt csv/m1.csv 2>/dev/null && bad "merge-manifests took a .txt" || ok

# --- Kubernetes: the Indexed Job ----------------------------------------------------------------
py=python3
$py -c 'import yaml' 2>/dev/null || py=/usr/bin/python3
if ! $py -c 'import yaml' 2>/dev/null; then
  echo "cluster_examples: no PyYAML (Debian python3-yaml): the Kubernetes part is skipped"
else
  $py - "$cluster/roses-job.yaml" <<'PY' >k8s.env || bad "the Job's fields"
import shlex, sys, yaml
docs = {d["kind"]: d for d in yaml.safe_load_all(open(sys.argv[1]))}
job = docs["Job"]["spec"]
pod = job["template"]["spec"]
c = pod["containers"][0]
env = {e["name"]: e["value"] for e in c["env"]}
assert job["completionMode"] == "Indexed", "completionMode"
assert job["completions"] == job["parallelism"] == int(env["SHARDS"]), "completions = parallelism = SHARDS"
assert pod["restartPolicy"] == "Never"
mounts = {m["mountPath"] for m in c["volumeMounts"]}
assert env["GRAMMAR"].rsplit("/", 1)[0] in mounts and env["OUT"].startswith(tuple(mounts)), "mounts"
assert c["command"] == ["/bin/sh", "-c"] and len(c["args"]) == 1
open("rose.plant", "w").write(docs["ConfigMap"]["data"]["rose.plant"])
print("script=" + shlex.quote(c["args"][0]))
PY
  . ./k8s.env
  "$plant" check rose.plant 2>/dev/null && ok || bad "the ConfigMap's grammar does not compile"
  mkdir -p bin && ln -s "$plant" bin/plant
  for index in 0 1 2; do
    PATH=$tmp/bin:$PATH JOB_COMPLETION_INDEX=$index SHARDS=3 SEEDS=1..30 GRAMMAR=$bush OUT=k8s JOBS=2 \
      /bin/sh -c "$script" 2>/dev/null || bad "pod $index failed"
  done
  "$cluster/merge-manifests" k8s/manifest.jsonl k8s/manifest-*.jsonl
  same_run "kubernetes indexed job" k8s k8s/manifest.jsonl
fi

echo "cluster_examples: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
