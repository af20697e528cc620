#!/usr/bin/env bash
# Installs the npm packages pinned in tests/gltf/package-lock.json (gltf-validator, three) into
# tests/gltf/node_modules with `npm ci` when any is missing or at another version; later runs
# reuse them. Sourced or run by the scripts in this folder.
set -euo pipefail
gltf_dir="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
stale="$(node -e '
  const dir = process.argv[1];
  const lock = require(dir + "/package-lock.json").packages;
  for (const [path, pkg] of Object.entries(lock)) {
    if (!path.startsWith("node_modules/")) continue;
    let have = null;
    try { have = require(dir + "/" + path + "/package.json").version; } catch {}
    if (have !== pkg.version) { console.log(path); break; }
  }' "$gltf_dir")"
if [[ -n "$stale" ]]; then
    (cd "$gltf_dir" && npm ci --no-audit --no-fund --loglevel=error) >&2
fi
