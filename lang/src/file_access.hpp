// Which files a grammar may read: those under the main grammar's folder, the library folders
// (-I, PLANT_PATH, the standard library) and the folders the user allows with --allow-read,
// judged after symbolic links and `..` are resolved (docs/language.md, "Imports").
#pragma once

#include "plant/compiler.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace plant {

// The standard library's folder: PREFIX/share/plant/stdlib beside an installed PREFIX/bin/plant
// (so a moved install still finds its own), else, for a program whose executable lies in the build
// folder it was configured in, the source tree's stdlib/; else the path an install would have
// (missing, so that a failed import names it). Found once per process.
const std::string& standard_library_dir();

// The folders searched for `import name`: -I, then PLANT_PATH, then the standard library.
std::vector<std::string> library_dirs(const CompileOptions& options);

class FileAccess {
  public:
    FileAccess(const std::string& main_file, const CompileOptions& options);

    // The file's identity: its path with symbolic links and `..` resolved; empty when it does
    // not exist (or a folder on the way cannot be searched).
    static std::string identity(const std::string& path);

    // Whether a file of that identity lies under one of the allowed folders.
    bool allowed(const std::string& identity) const;

    // The message for a refused file, naming it as written.
    static std::string refusal(const std::string& written);

  private:
    std::vector<std::filesystem::path> roots_;
};

} // namespace plant
