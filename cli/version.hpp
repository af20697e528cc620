// plant's version (project VERSION in CMakeLists.txt) and the git commit it was built from
// ("unknown" outside a git work tree), written into version.cpp at build time by
// cmake/version.cmake.
#pragma once

namespace plant::cli {

extern const char* const kVersion;
extern const char* const kCommit;

} // namespace plant::cli
