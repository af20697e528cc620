#!/usr/bin/env bash
# Every grammar in grammars/ grows into a GLB that the Khronos validator reports with 0 errors.
#   tests/gltf/all-grammars.sh PLANT
set -euo pipefail
plant=$(realpath "${1:?usage: all-grammars.sh PLANT}")
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
files=()
while IFS= read -r g; do
  name=$(echo "${g#"$repo"/grammars/}" | tr '/' '_')
  out="$tmp/${name%.plant}.glb"
  # the grammar's own `# args:` line, as the golden runner uses it
  args=$(sed -n 's/^# args: //p' "$g" | head -1)
  # the climber figures at 20 steps: their whole runs (fig10_dome alone about 25 s) are the golden
  # files' and the climber tests'; the first 20 steps write the same kinds of mesh, with leaves
  case $g in */grammars/climbers/*) args="$args -n 20" ;; esac
  # shellcheck disable=SC2086
  (cd "$(dirname "$g")" && "$plant" run "$(basename "$g")" $args -o "$out") || { echo "FAIL plant run $g"; exit 1; }
  files+=("$out")
done < <(find "$repo/grammars" -name '*.plant' | sort)
bash "$here/run" "${files[@]}"
echo "${#files[@]} passed, 0 failed"
