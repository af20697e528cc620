#!/usr/bin/env bash
# Installs the npm packages pinned in tests/gltf/package-lock.json (gltf-validator, three) into
# tests/gltf/node_modules, with the same pinned `npm ci` the viewer uses (viewer/install.sh DIR):
# only when one is missing or at another version. Run by the scripts in this folder.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
exec bash "$here/../../viewer/install.sh" "$here"
