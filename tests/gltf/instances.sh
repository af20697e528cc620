#!/usr/bin/env bash
# EXT_mesh_gpu_instancing as plant writes it, checked where the Khronos validator does not look:
# the rose grammars (leaves, leaflets and petals placed thousands of times), a hand-made nested
# scene (tests/unit/runtime/nested_scene.hpp: leaves in branches of two lengths in two trees) and
# the weeping willow (docs/willow.md: leaves in weeping branches in trees, one tree and a row seen
# with a camera).
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

# The willow: Fig. 5(d) (t = 8 at view depth 5: 960 weeping branches of 9 leaves, one leaf mesh
# and one weeping-branch mesh, each one instanced node), and the row with a camera (a view depth
# per tree: 480 weeping branches a tree, 10 + 8 + 7 + 5 + 3 + 1 leaves each from near to far).
willow="$repo/grammars/willow"
(cd "$willow" && "$plant" run fig05_near.plant -o "$tmp/fig05_near.glb" &&
  "$plant" run fig05_near.plant --no-gpu-instancing -o "$tmp/fig05_near.nodes.glb" &&
  "$plant" run fig05_near.plant --flatten -o "$tmp/fig05_near.flat.glb" &&
  "$plant" run row.plant --camera 12,4,16 -o "$tmp/row.glb" &&
  "$plant" run row.plant --camera 12,4,16 --no-gpu-instancing -o "$tmp/row.nodes.glb") ||
  { echo "FAIL plant run grammars/willow"; exit 1; }
near=(--expect "Willow(8, 0)@5/WeepingBranch(12)@5/leaf=8640"
      --expect "Willow(8, 0)@5/WeepingBranch(12)@5/tubes=960")
row=(--expect "Willow(7, 1)@3/WeepingBranch(12)@3/leaf=16320"
     --expect "Willow(7, 1)@3/WeepingBranch(12)@3/tubes=2880")
node "$here/instances.mjs" --require "${near[@]}" "$tmp/fig05_near.glb"
node "$here/instances.mjs" --require "${row[@]}" "$tmp/row.glb"
node "$here/validate.mjs" "$tmp/fig05_near.glb" "$tmp/fig05_near.nodes.glb" "$tmp/fig05_near.flat.glb" \
  "$tmp/row.glb" "$tmp/row.nodes.glb"
node "$here/three.mjs" "${near[@]}" "$tmp/fig05_near.glb" "$tmp/fig05_near.nodes.glb"
node "$here/three.mjs" "${row[@]}" "$tmp/row.glb" "$tmp/row.nodes.glb"
# the bark: the standard library's image once, on the tree's tubes only (the weeping branches keep
# their twig colour and the leaves theirs)
node "$here/textures.mjs" --image "$repo/stdlib/textures/bark.png" --textured "Willow(8, 0)@5/tubes" \
  --plain "Willow(8, 0)@5/WeepingBranch(12)@5/tubes" --plain "Willow(8, 0)@5/WeepingBranch(12)@5/leaf" \
  "$tmp/fig05_near.glb" "$tmp/fig05_near.nodes.glb"
# instanced, the tree is at least 5 times smaller than flattened (docs/willow.md)
inst_size=$(stat -c %s "$tmp/fig05_near.glb")
flat_size=$(stat -c %s "$tmp/fig05_near.flat.glb")
((inst_size * 5 <= flat_size)) ||
  { echo "FAIL fig05_near.glb is $inst_size bytes, not 5 times smaller than flattened ($flat_size)"; exit 1; }
echo "instances: ${#instanced[@]} grammars, the nested scene and the willows passed"
