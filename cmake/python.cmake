# The Python module (python/, docs/api.md): `import plant`, built with pybind11 into
# build/python/plant/ and installed into PREFIX/PLANT_PYTHON_INSTALL_DIR.
#   -DPLANT_PYTHON=AUTO  (default) build it when pybind11 and a Python 3 with its headers are found
#   -DPLANT_PYTHON=ON    the same, but stop when they are not found
#   -DPLANT_PYTHON=OFF   do not build it
# -DPython_EXECUTABLE=... picks the interpreter; by default the first of `python3` on PATH and
# /usr/bin/python3 that can import numpy (a pyenv or venv python3 first on PATH may lack
# Debian's python3-numpy, which scripts/install-deps installs for /usr/bin/python3).
set(PLANT_PYTHON AUTO CACHE STRING "Build the Python module: AUTO (when pybind11 is found), ON or OFF")
set_property(CACHE PLANT_PYTHON PROPERTY STRINGS AUTO ON OFF)
set(PLANT_PYTHON_BUILT OFF)

# (not in the sanitizer builds: an extension built with ASan cannot load into Debian's python3)
if(PLANT_SANITIZE)
  message(STATUS "Python module: not built in a sanitizer build")
elseif(NOT PLANT_PYTHON STREQUAL "OFF")
  if(NOT Python_EXECUTABLE)
    find_program(plant_path_python3 NAMES python3 NO_CACHE)
    foreach(candidate ${plant_path_python3} /usr/bin/python3)
      if(EXISTS ${candidate})
        execute_process(COMMAND ${candidate} -c "import numpy" RESULT_VARIABLE numpy_missing
                        OUTPUT_QUIET ERROR_QUIET)
        if(numpy_missing EQUAL 0)
          set(Python_EXECUTABLE ${candidate} CACHE FILEPATH "The Python the module is built for")
          break()
        endif()
      endif()
    endforeach()
  endif()
  find_package(Python 3.8 COMPONENTS Interpreter Development.Module QUIET)
  set(PYBIND11_FINDPYTHON ON)
  if(Python_FOUND)
    find_package(pybind11 2.6 CONFIG QUIET)
  endif()
  set(plant_numpy_found FALSE)
  if(Python_FOUND)
    execute_process(COMMAND ${Python_EXECUTABLE} -c "import numpy" RESULT_VARIABLE numpy_missing
                    OUTPUT_QUIET ERROR_QUIET)
    if(numpy_missing EQUAL 0)
      set(plant_numpy_found TRUE)
    endif()
  endif()
  if(Python_FOUND AND pybind11_FOUND AND plant_numpy_found)
    set(PLANT_PYTHON_BUILT ON)
  elseif(PLANT_PYTHON STREQUAL "ON")
    message(FATAL_ERROR "PLANT_PYTHON=ON but the Python module cannot be built: "
                        "pybind11 (found: ${pybind11_FOUND}), Python 3 with its headers (found: "
                        "${Python_FOUND}) and NumPy (found: ${plant_numpy_found}) are needed; "
                        "scripts/install-deps installs pybind11-dev, python3-dev and python3-numpy")
  else()
    message(STATUS "Python module: not built (pybind11 found: ${pybind11_FOUND}, Python 3 headers found: "
                   "${Python_FOUND}, NumPy found: ${plant_numpy_found}); scripts/install-deps installs pybind11-dev, python3-dev and "
                   "python3-numpy, or configure with -DPLANT_PYTHON=OFF to silence this")
  endif()
endif()

if(PLANT_PYTHON_BUILT)
  # Where `cmake --install` puts the package, relative to the prefix. Debian's python3 (which has
  # a deb_system scheme) reads PREFIX/lib/python3.X/dist-packages for /usr and /usr/local alike;
  # any other Python, its own platlib under the prefix (lib/python3.X/site-packages).
  execute_process(
    COMMAND ${Python_EXECUTABLE} -c
            "import sysconfig, sys; v = '%d.%d' % sys.version_info[:2]; print('lib/python%s/dist-packages' % v if 'deb_system' in sysconfig.get_scheme_names() else sysconfig.get_path('platlib', 'posix_prefix', vars={'base': '.', 'platbase': '.'})[2:])"
    OUTPUT_VARIABLE plant_python_dir OUTPUT_STRIP_TRAILING_WHITESPACE)
  set(PLANT_PYTHON_INSTALL_DIR ${plant_python_dir} CACHE STRING
      "Where cmake --install puts the Python package `plant`, relative to the prefix")
  message(STATUS "Python module: built for ${Python_EXECUTABLE} (${Python_VERSION}), pybind11 "
                 "${pybind11_VERSION}; installed into PREFIX/${PLANT_PYTHON_INSTALL_DIR}")
  # The static libraries end up in a shared object: position-independent code. Without semantic
  # interposition GCC still inlines and calls them directly, as in a program (docs/api.md).
  set_target_properties(plant_common plant_lang plant_physics plant_runtime plant_outputs PROPERTIES
                        POSITION_INDEPENDENT_CODE ON)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    foreach(lib plant_common plant_lang plant_physics plant_runtime plant_outputs)
      target_compile_options(${lib} PRIVATE -fno-semantic-interposition)
    endforeach()
  endif()
  add_subdirectory(python)
  # the plant Debian package holds the module (the runtime component); NumPy makes its arrays
  set(CPACK_DEBIAN_RUNTIME_PACKAGE_RECOMMENDS "python3-numpy")
endif()
