#include "file_access.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>

#ifndef PLANT_STDLIB_DIR
#define PLANT_STDLIB_DIR ""
#endif

namespace plant {

namespace fs = std::filesystem;

std::vector<std::string> library_dirs(const CompileOptions& options) {
    std::vector<std::string> dirs = options.include_dirs;
    if (const char* pp = std::getenv("PLANT_PATH")) {
        std::string s = pp;
        std::size_t b = 0;
        while (b <= s.size()) {
            std::size_t e = s.find(':', b);
            if (e == std::string::npos) e = s.size();
            if (e > b) dirs.push_back(s.substr(b, e - b));
            b = e + 1;
        }
    }
    if (std::string(PLANT_STDLIB_DIR).size()) dirs.emplace_back(PLANT_STDLIB_DIR);
    return dirs;
}

std::string FileAccess::identity(const std::string& path) {
    std::error_code ec;
    fs::path p = fs::canonical(path.empty() ? fs::path(".") : fs::path(path), ec);
    return ec ? std::string() : p.string();
}

FileAccess::FileAccess(const std::string& main_file, const CompileOptions& options) {
    auto add = [&](const std::string& dir) {
        std::string id = identity(dir.empty() ? "." : dir);
        if (!id.empty()) roots_.emplace_back(id);
    };
    add(fs::path(main_file).parent_path().string());
    for (const auto& d : library_dirs(options)) add(d);
    for (const auto& d : options.allow_read) add(d);
}

bool FileAccess::allowed(const std::string& id) const {
    const fs::path p(id);
    return std::any_of(roots_.begin(), roots_.end(), [&](const fs::path& root) {
        // under the root component by component: /a/bc is not under /a/b
        auto [r, q] = std::mismatch(root.begin(), root.end(), p.begin(), p.end());
        return r == root.end() || (std::next(r) == root.end() && r->empty());
    });
}

std::string FileAccess::refusal(const std::string& written) {
    return fmt::format("'{}' is outside the folders this grammar may read (its own folder, -I and "
                       "PLANT_PATH folders, the standard library); to allow it, pass --allow-read with "
                       "its folder",
                       written);
}

} // namespace plant
