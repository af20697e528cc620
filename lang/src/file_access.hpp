// Which files a grammar may read: those under the main grammar's folder, the library folders
// (-I, PLANT_PATH, the standard library) and the folders the user allows with --allow-read,
// judged after symbolic links and `..` are resolved (docs/language.md, "Imports").
#pragma once

#include "plant/compiler.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace plant {

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
