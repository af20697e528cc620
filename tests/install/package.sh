#!/usr/bin/env bash
# The Debian packages (docs/install.md): cpack -G DEB makes plant and plant-dev; their control
# fields are checked, both are unpacked with dpkg -x into a scratch root, and the unpacked plant
# grows a rose with the source tree out of reach, while the headers and CMake package are there.
# With PYTHON and PYTHON_DIR (the Python module was built), plant holds the Python package too,
# and the unpacked one grows the rose.
#   package.sh CPACK BUILD_DIR SOURCE_DIR [PYTHON PYTHON_DIR]
set -u
cpack=${1:?usage: package.sh CPACK BUILD_DIR SOURCE_DIR [PYTHON PYTHON_DIR]}
build=$(realpath "${2:?}")
src=$(realpath "${3:?}")
python=${4:-}
pydir=${5:-}
. "$(dirname "$0")/lib.sh"
golden=$src/grammars/rose/fig12c.mesh.txt

if ! (cd "$build" && "$cpack" -G DEB -B "$tmp/pkg") >"$tmp/cpack.log" 2>&1; then
  cat "$tmp/cpack.log"
  exit 1
fi
deb=$(ls "$tmp"/pkg/plant_*.deb)
dev=$(ls "$tmp"/pkg/plant-dev_*.deb)
version=$(sed -n 's/^project(plant VERSION \([0-9.]*\).*/\1/p' "$src/CMakeLists.txt")
check "dpkg-deb reads plant's control" 0 dpkg-deb -f "$deb" Package Version Maintainer Depends Description
control=$tmp/control.txt
cp "$tmp/stdout" "$control"
grep '^Depends:' "$control" # in the test's log
contains "package name" "$control" "Package: plant"
contains "package version" "$control" "Version: $version"
contains "maintainer" "$control" "Maintainer: "
contains "description" "$control" "Description: interpreter for the .plant L-system language"
for lib in libc6 libstdc++6 libfmt9 libedit2 libopenmesh libstb0 libtinygltf libcpp-httplib; do
  contains "plant depends on $lib" "$control" "$lib"
done
check "dpkg-deb reads plant-dev's control" 0 dpkg-deb -f "$dev" Package Depends
cp "$tmp/stdout" "$tmp/control-dev.txt"
contains "plant-dev depends on plant" "$tmp/control-dev.txt" "plant (= $version)"
contains "plant-dev depends on the -dev packages" "$tmp/control-dev.txt" "libfmt-dev"

root=$tmp/root
check "dpkg -x plant" 0 dpkg -x "$deb" "$root"
check "dpkg -x plant-dev" 0 dpkg -x "$dev" "$root"
for f in usr/bin/plant usr/lib/plant/plant-view-server.so usr/share/plant/stdlib/rose.plant usr/share/plant/stdlib/textures/bark.png \
  usr/share/doc/plant/README.md usr/share/man/man1/plant.1 usr/include/plant/compiler.hpp \
  usr/lib/libplant_runtime.a usr/lib/cmake/plant/plantConfig.cmake; do
  exists "the packages hold $f" "$root/$f"
done
dpkg-deb -c "$dev" >"$tmp/dev-files"
lacks "plant-dev holds no program (plant does)" "$tmp/dev-files" "usr/bin/plant"
dpkg-deb -c "$deb" >"$tmp/files"
lacks "plant holds no headers (plant-dev does)" "$tmp/files" "usr/include"

mkdir "$tmp/work"
cp "$src/grammars/rose/fig12c.plant" "$tmp/work/"
cd "$tmp/work" || exit 1
if can_hide; then
  run=(hidden "$src")
else
  run=()
  echo "SKIP hiding the source tree: no private mount namespace here (unshare -rm)"
fi
check "the unpacked plant grows a rose" 0 "${run[@]}" "$root/usr/bin/plant" run fig12c.plant -o rose.mesh.txt
same "the unpacked plant's rose matches the golden" rose.mesh.txt "$golden"
printf 'import nosuchlib;\naxiom: F;\n' >missing.plant
check "the unpacked plant: a missing library" 66 "${run[@]}" "$root/usr/bin/plant" check missing.plant
contains "it searched the unpacked stdlib" "$tmp/stderr" "$root/usr/share/plant/stdlib/nosuchlib.plant"
lacks "and not the source tree" "$tmp/stderr" "$src"
if [ -n "$python" ]; then
  exists "plant holds the Python package" "$root/usr/$pydir/plant/__init__.py"
  check "the unpacked Python package grows a rose" 0 "${run[@]}" env PYTHONPATH="$root/usr/$pydir" \
    PYTHONDONTWRITEBYTECODE=1 "$python" -c \
    'import plant; plant.compile("fig12c.plant").derive().save("py.mesh.txt"); print(plant.STDLIB)'
  same "the unpacked Python package's rose matches the golden" py.mesh.txt "$golden"
  contains "it reads the unpacked stdlib" "$tmp/stdout" "$root/usr/share/plant/stdlib"
fi
finish
