#!/usr/bin/env bash
# plant --version (the project VERSION and the git commit, written at build time by
# cmake/version.cmake) and the man page made from the commands' help (plant help --man).
#   version.sh PLANT CMAKE BUILD_DIR SOURCE_DIR
set -u
plant=$(realpath "${1:?usage: version.sh PLANT CMAKE BUILD_DIR SOURCE_DIR}")
cmake=${2:?}
build=$(realpath "${3:?}")
src=$(realpath "${4:?}")
. "$(dirname "$0")/lib.sh"

version=$(sed -n 's/^project(plant VERSION \([0-9.]*\).*/\1/p' "$src/CMakeLists.txt")
commit=unknown
if [ "$(git -C "$src" rev-parse --show-toplevel 2>/dev/null)" = "$src" ]; then
  commit=$(git -C "$src" rev-parse --short=12 HEAD)
fi
check "plant --version" 0 "$plant" --version
echo "plant $version (commit $commit)" >"$tmp/want"
same "--version names the version and the commit" "$tmp/stdout" "$tmp/want"

# the commit outside git: unknown, also in a folder inside somebody else's repository
gen() { "$cmake" -DSOURCE_DIR="$1" -DOUT="$tmp/version.cpp" -DVERSION=9.8.7 -DGIT_COMMIT="${2:-}" \
  -P "$src/cmake/version.cmake"; }
mkdir "$tmp/plain"
gen "$tmp/plain"
contains "no git: the commit is unknown" "$tmp/version.cpp" 'kCommit = "unknown"'
contains "the version is the one given" "$tmp/version.cpp" 'kVersion = "9.8.7"'
git init -q "$tmp/repo" && git -C "$tmp/repo" -c user.name=t -c user.email=t@t commit -q --allow-empty -m t
mkdir "$tmp/repo/sources"
gen "$tmp/repo/sources"
contains "inside another repository: unknown" "$tmp/version.cpp" 'kCommit = "unknown"'
gen "$tmp/repo"
contains "at the top of a work tree: its commit" "$tmp/version.cpp" \
  "kCommit = \"$(git -C "$tmp/repo" rev-parse --short=12 HEAD)\""
gen "$tmp/plain" 0123abcd
contains "-DPLANT_GIT_COMMIT names the commit" "$tmp/version.cpp" 'kCommit = "0123abcd"'

# the man page: what plant help --man prints, valid for groff, naming every command and topic
check "plant help --man" 0 "$plant" help --man
same "the built plant.1 is plant help --man" "$build/plant.1" "$tmp/stdout"
check "help --man takes no topic" 64 "$plant" help --man run
if command -v groff >/dev/null; then
  check "groff reads plant.1 without warnings" 0 groff -man -Tutf8 -ww -z "$build/plant.1"
  if [ -s "$tmp/stderr" ]; then
    fail=$((fail + 1))
    echo "FAIL groff warns about plant.1:"
    head -5 "$tmp/stderr"
  fi
  groff -man -Tutf8 "$build/plant.1" 2>/dev/null | sed 's/.\x08//g' >"$tmp/man.txt"
  "$plant" help --names >"$tmp/names"
  while read -r name; do contains "man page names $name" "$tmp/man.txt" "$name"; done <"$tmp/names"
  for option in --output --seed --allow-read --version PLANT_PATH share/plant/stdlib; do
    contains "man page names $option" "$tmp/man.txt" "$option"
  done
else
  echo "SKIP groff checks: groff is not installed (scripts/install-deps installs groff-base)"
fi
finish
