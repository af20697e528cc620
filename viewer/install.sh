#!/usr/bin/env bash
# Installs the npm packages pinned in DIR/package-lock.json (default: this folder, three.js for
# the page `plant view` serves) into DIR/node_modules with `npm ci` when any is missing or at
# another version; later runs reuse them. Run it before building plant so that three.js is built
# into the program (docs/view.md); tests/view/run runs it for its own folder too.
set -euo pipefail
dir="$(cd "${1:-$(dirname "${BASH_SOURCE[0]}")}" && pwd)"
# Tests run in parallel and several install into the same folder: one at a time (npm ci removes
# node_modules first, so a second npm ci or a check running beside it would see half a tree).
exec 9>"$dir/.install.lock"
flock 9
stale="$(node -e '
  const dir = process.argv[1];
  const lock = require(dir + "/package-lock.json").packages;
  for (const [path, pkg] of Object.entries(lock)) {
    if (!path.startsWith("node_modules/")) continue;
    let have = null;
    try { have = require(dir + "/" + path + "/package.json").version; } catch {}
    if (have !== pkg.version) { console.log(path); break; }
  }' "$dir")"
if [[ -n "$stale" ]]; then
    (cd "$dir" && npm ci --no-audit --no-fund --loglevel=error) >&2
fi
