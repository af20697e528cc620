#!/usr/bin/env bash
# The installed tree (docs/install.md): `cmake --install` into a prefix, the prefix moved
# elsewhere, then the moved install grows a rose from a grammar outside the source tree, finds
# only its own standard library (the import search names it and never the source tree; with
# the source tree hidden by an empty mount it still works), and the C++ example builds against
# its CMake package and grows the same rose. With PYTHON and PYTHON_DIR (the Python module was
# built; PYTHON_DIR is where it installs under the prefix), tests/python runs against the moved
# install's package too, also with the source tree hidden.
#   install.sh CMAKE BUILD_DIR SOURCE_DIR [PYTHON PYTHON_DIR]
set -u
cmake=${1:?usage: install.sh CMAKE BUILD_DIR SOURCE_DIR [PYTHON PYTHON_DIR]}
build=$(realpath "${2:?}")
src=$(realpath "${3:?}")
python=${4:-}
pydir=${5:-}
. "$(dirname "$0")/lib.sh"
golden=$src/grammars/rose/fig12c.mesh.txt

# install, then move the prefix: nothing may depend on where it was installed (plant view's
# server module included)
if ! "$cmake" --install "$build" --prefix "$tmp/first" >"$tmp/install.log" 2>&1; then
  cat "$tmp/install.log"
  exit 1
fi
mv "$tmp/first" "$tmp/moved"
p=$tmp/moved
for f in bin/plant lib/plant/plant-view-server.so share/plant/stdlib/rose.plant share/plant/stdlib/textures/bark.png \
  share/doc/plant/README.md share/doc/plant/install.md share/doc/plant/api.md share/man/man1/plant.1 \
  include/plant/compiler.hpp include/plant/derive.hpp include/plant/scene.hpp include/plant/export.hpp \
  include/plant/random.hpp include/plant/physics/world.hpp lib/libplant_lang.a lib/libplant_runtime.a \
  lib/libplant_physics.a lib/cmake/plant/plantConfig.cmake lib/cmake/plant/plantConfigVersion.cmake \
  lib/cmake/plant/plantTargets.cmake; do
  exists "installed $f" "$p/$f"
done
(cd "$src/stdlib" && find . -type f | sort) >"$tmp/stdlib.src"
(cd "$p/share/plant/stdlib" && find . -type f | sort) >"$tmp/stdlib.installed"
same "the whole standard library is installed" "$tmp/stdlib.src" "$tmp/stdlib.installed"
for doc in "$src"/docs/*.md; do exists "installed doc $(basename "$doc")" "$p/share/doc/plant/$(basename "$doc")"; done

# a rose grown by the moved install from a grammar outside the source tree: the golden counts
mkdir "$tmp/work"
cp "$src/grammars/rose/fig12c.plant" "$tmp/work/"
cd "$tmp/work" || exit 1
check "moved install runs a rose" 0 "$p/bin/plant" run fig12c.plant -o rose.glb -o rose.mesh.txt
same "moved install's rose matches the golden" rose.mesh.txt "$golden"

# plant view from the moved install: it loads the server module from lib/plant/ and serves
"$p/bin/plant" view fig12c.plant --port 0 >view.out 2>view.err &
view_pid=$!
for _ in $(seq 100); do grep -qs "http://" view.out && break; sleep 0.1; done
url=$(grep -o 'http://127.0.0.1:[0-9]*/' view.out)
if [ -n "$url" ] && curl -s "${url}api/state" | grep -q '"version"'; then pass=$((pass + 1)); else
  fail=$((fail + 1))
  echo "FAIL the moved install's plant view serves"
  sed 's/^/  /' view.err | head -5
fi
kill -INT "$view_pid" 2>/dev/null
wait "$view_pid"

# the search for a library: -I, then PLANT_PATH, then the install's stdlib, never the source tree
printf 'import nosuchlib;\naxiom: F;\n' >missing.plant
mkdir -p inc pp
check "import nosuchlib fails" 66 env PLANT_PATH="$tmp/work/pp" "$p/bin/plant" check missing.plant -I "$tmp/work/inc"
contains "import names the paths searched, in order" "$tmp/stderr" \
  "(searched $tmp/work/inc/nosuchlib.plant, $tmp/work/pp/nosuchlib.plant, $p/share/plant/stdlib/nosuchlib.plant)"
lacks "a moved install never searches the source tree" "$tmp/stderr" "$src"

# through a symbolic link (/usr/local/bin/plant -> /opt/plant/bin/plant) it is still the install
ln -s "$p/bin/plant" "$tmp/plant-link"
check "plant through a symbolic link" 66 "$tmp/plant-link" check missing.plant
contains "a linked plant searches its install's stdlib" "$tmp/stderr" "$p/share/plant/stdlib/nosuchlib.plant"

# an install without rose.plant cannot import rose: it does not fall back on the source tree
cp -r "$p" "$tmp/bare"
rm "$tmp/bare/share/plant/stdlib/rose.plant"
check "install without rose.plant" 66 "$tmp/bare/bin/plant" check fig12c.plant
contains "names the missing library" "$tmp/stderr" "cannot find library 'rose'"
lacks "and searched no source tree" "$tmp/stderr" "$src"

# a program copied out of its build tree reads no source tree either (the old behaviour did)
mkdir -p "$tmp/lonely/bin"
cp "$build/plant" "$tmp/lonely/bin/"
check "copied build-tree program" 66 "$tmp/lonely/bin/plant" check missing.plant
contains "names where an install's stdlib would be" "$tmp/stderr" "$tmp/lonely/share/plant/stdlib/nosuchlib.plant"
lacks "copied build-tree program ignores the source tree" "$tmp/stderr" "$src"
# while the build tree's own program reads the source tree's stdlib
check "build-tree program" 66 "$build/plant" check missing.plant
contains "the build tree's program searches the source stdlib" "$tmp/stderr" "$src/stdlib/nosuchlib.plant"

# the C++ API: examples/cpp against the moved install's CMake package
launcher=()
if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
export CCACHE_BASEDIR=$tmp # the install's paths become relative: the same from run to run
check "configure examples/cpp" 0 "$cmake" -S "$src/examples/cpp" -B "$tmp/example" -G Ninja \
  -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$p" "${launcher[@]}"
check "build examples/cpp" 0 "$cmake" --build "$tmp/example"
check "the example grows the rose" 0 "$tmp/example/grow" fig12c.plant api.glb
cp "$tmp/stdout" counts.txt
grep -E '^(vertices|triangles) ' "$golden" >golden-counts.txt
grep -E '^(vertices|triangles) ' counts.txt >api-counts.txt
same "the example's counts match plant run's" api-counts.txt golden-counts.txt
contains "the example counts modules" counts.txt "modules "
if [ "$(head -c 4 api.glb)" = "glTF" ]; then pass=$((pass + 1)); else
  fail=$((fail + 1))
  echo "FAIL the example's api.glb is not a GLB"
fi

# the Python module: tests/python, with the grammar and docs it reads copied out of the source
# tree, against the moved install's package (the tests check it is that one, reading that stdlib)
if [ -n "$python" ]; then
  exists "installed Python package" "$p/$pydir/plant/__init__.py"
  mkdir -p "$tmp/py/grammars/rose" "$tmp/py/docs" "$tmp/py/tests"
  cp -r "$src/tests/python" "$tmp/py/tests/"
  cp "$src/grammars/rose/fig12c.plant" "$src/grammars/rose/fig12c.mesh.txt" "$tmp/py/grammars/rose/"
  cp "$src/docs/api.md" "$tmp/py/docs/"
  pytest=(env PYTHONPATH="$p/$pydir" PYTHONDONTWRITEBYTECODE=1 PLANT_SOURCE_DIR="$tmp/py" PLANT_EXE="$p/bin/plant"
    PLANT_EXPECT_PREFIX="$p" "$python" -m pytest -q -p no:cacheprovider -rs "$tmp/py/tests/python")
  check "the Python tests against the install" 0 "${pytest[@]}"
  tail -3 "$tmp/stdout"
  lacks "no Python test skipped" "$tmp/stdout" "skipped"
fi

# with the source tree (and the build tree in it) hidden: the install and the example still work
if can_hide; then
  check "moved install, source tree hidden" 0 hidden "$src" "$p/bin/plant" run fig12c.plant -o hidden.mesh.txt
  same "rose with the source tree hidden" hidden.mesh.txt "$golden"
  check "example, source tree hidden" 0 hidden "$src" "$tmp/example/grow" fig12c.plant hidden.glb
  check "copied program, source tree hidden, finds no rose" 66 hidden "$src" "$tmp/lonely/bin/plant" check fig12c.plant
  if [ -n "$python" ]; then
    check "the Python tests against the install, source tree hidden" 0 hidden "$src" "${pytest[@]}"
    tail -3 "$tmp/stdout"
  fi
else
  echo "SKIP hiding the source tree: no private mount namespace here (unshare -rm)"
fi
finish
