#!/usr/bin/env bash
# EXT_mesh_gpu_instancing as plant writes it, checked where the Khronos validator does not look:
# the rose grammars (leaves, leaflets and petals placed thousands of times) and a hand-made nested
# scene (tests/unit/runtime/nested_scene.hpp: leaves in branches of two lengths in two trees).
#   tests/gltf/instances.sh PLANT GLTF_NESTED_SCENE
# instances.mjs checks the instance accessors; three.mjs loads every file with three.js and
# compares its InstancedMeshes with the --no-gpu-instancing file of the same scene.
set -euo pipefail
plant=$(realpath "${1:?usage: instances.sh PLANT GLTF_NESTED_SCENE}")
nested=$(realpath "${2:?usage: instances.sh PLANT GLTF_NESTED_SCENE}")
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
bash "$here/install.sh"

instanced=()
pairs=()
for g in "$repo"/grammars/rose/*.plant; do
  name=$(basename "$g" .plant)
  args=$(sed -n 's/^# args: //p' "$g" | head -1)
  # shellcheck disable=SC2086
  (cd "$(dirname "$g")" && "$plant" run "$name.plant" $args -o "$tmp/$name.glb" &&
    "$plant" run "$name.plant" $args --no-gpu-instancing -o "$tmp/$name.nodes.glb") ||
    { echo "FAIL plant run $g"; exit 1; }
  instanced+=("$tmp/$name.glb")
  pairs+=("$tmp/$name.glb" "$tmp/$name.nodes.glb")
done

"$nested" "$tmp" || { echo "FAIL gltf_nested_scene"; exit 1; }
# the nested scene: one mesh and one instanced node for the leaves of both branch lengths
expect=(--expect tree/long/leaf=144 --expect tree/tubes=2 --expect tree/long/tubes=8
        --expect tree/short/tubes=8 --expect odd=1)

node "$here/instances.mjs" --require "${instanced[@]}"
node "$here/instances.mjs" --require "${expect[@]}" "$tmp/nested.glb" "$tmp/nested.gltf"
node "$here/validate.mjs" "$tmp/nested.glb" "$tmp/nested.nodes.glb" "$tmp/nested.flat.glb" "$tmp/nested.gltf"
node "$here/three.mjs" "${pairs[@]}"
node "$here/three.mjs" "${expect[@]}" "$tmp/nested.glb" "$tmp/nested.nodes.glb" "$tmp/nested.gltf" "$tmp/nested.nodes.glb"
# the forest: a node per tree, each with the one leaf accessor set of 1,000 placements
node "$here/instances.mjs" --require --expect tree/leaf=1000 "$tmp/forest.glb"
node "$here/validate.mjs" "$tmp/forest.glb"
node "$here/three.mjs" --expect tree/leaf=1000 "$tmp/forest.glb" "$tmp/forest.nodes.glb"
echo "instances: ${#instanced[@]} grammars and the nested scene passed"
