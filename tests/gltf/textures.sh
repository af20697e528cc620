#!/usr/bin/env bash
# Textures in glTF (docs/language.md, textures): tests/gltf/textures/bark.plant written as .glb and
# .gltf, with GPU instancing, plain nodes and flattened; each file passes the Khronos validator,
# holds the bark image once with the file's bytes on the trunk's and the instanced twigs' tubes
# while the leaves keep their colour (textures.mjs; the twigs' leaves are the same mesh as the
# trunk's, one material by colour and texture), and loads in three.js with the image on the
# textured materials (three.mjs, images not decoded under node).
#   tests/gltf/textures.sh PLANT
set -euo pipefail
plant=$(realpath "${1:?usage: textures.sh PLANT}")
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
bash "$here/install.sh"

cd "$here/textures"
# the copy beside the grammar is the standard library's bark
cmp bark.png "$here/../../stdlib/textures/bark.png"
"$plant" run bark.plant -o "$tmp/bark.glb" -o "$tmp/bark.gltf"
"$plant" run bark.plant --no-gpu-instancing -o "$tmp/bark.nodes.glb" -o "$tmp/bark.nodes.gltf"
"$plant" run bark.plant --flatten -o "$tmp/bark.flat.glb"

node "$here/validate.mjs" "$tmp"/*.glb "$tmp"/*.gltf
node "$here/textures.mjs" --image bark.png --textured tubes --plain leaf --textured 'Twig(2)/tubes' \
  "$tmp/bark.glb" "$tmp/bark.gltf" "$tmp/bark.nodes.glb" "$tmp/bark.nodes.gltf"
node "$here/textures.mjs" --image bark.png --textured plant --plain plant "$tmp/bark.flat.glb"
node "$here/three.mjs" "$tmp/bark.glb" "$tmp/bark.nodes.glb" "$tmp/bark.gltf" "$tmp/bark.nodes.gltf"
echo "textures: passed"
