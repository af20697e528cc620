# Debian packages by CPack (docs/install.md): `cpack -G DEB` in the build folder, or `make
# package`, writes plant_VERSION_ARCH.deb (the program, the standard library, docs and man page;
# its dependencies found by dpkg-shlibdeps from the libraries the program links) and
# plant-dev_VERSION_ARCH.deb (headers, static libraries and the CMake package; it depends on
# plant and on the -dev packages the headers and libraries need). Both install under /usr.
set(PLANT_PACKAGE_MAINTAINER "plant developers <plant-devel@example.org>"
    CACHE STRING "The Maintainer field of the Debian packages")

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME plant)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_CONTACT "${PLANT_PACKAGE_MAINTAINER}")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "interpreter for the .plant L-system language")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_COMPONENTS_ALL runtime dev)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_MAINTAINER "${PLANT_PACKAGE_MAINTAINER}")
set(CPACK_DEBIAN_PACKAGE_SECTION graphics)

set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME plant)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_SHLIBDEPS ON)
# plant repl loads libedit.so.2 with dlopen (cli/repl_main.cpp), which dpkg-shlibdeps cannot see
set(CPACK_DEBIAN_RUNTIME_PACKAGE_DEPENDS "libedit2")
set(CPACK_COMPONENT_RUNTIME_DESCRIPTION
    "interpreter for the .plant L-system language
 plant grows plants from parametric, context-sensitive and stochastic L-system grammars:
 it derives them, interprets the result with a 3D turtle, meshes the skeleton into
 generalized cylinders and organ surfaces, and writes glTF, OBJ, PLY, OFF, PNG and SVG.
 The package holds the program, its standard library (roses, climbers, willows), the
 documentation and the man page.")

set(CPACK_DEBIAN_DEV_PACKAGE_NAME plant-dev)
set(CPACK_DEBIAN_DEV_PACKAGE_SECTION libdevel)
set(CPACK_DEBIAN_DEV_PACKAGE_DEPENDS
    "plant (= ${PROJECT_VERSION}), libglm-dev, libfmt-dev, tao-pegtl-dev, libopenmesh-dev, libtinygltf-dev, libstb-dev")
set(CPACK_COMPONENT_DEV_DESCRIPTION
    "C++ API of plant, the L-system interpreter
 Headers, static libraries and a CMake package: find_package(plant) gives the target
 plant::plant, which compiles grammars, derives them, interprets, meshes and exports
 the result.")

include(CPack)
