#include "file_access.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>

// The source tree's standard library and the build folder the library was configured in
// (lang/CMakeLists.txt); a program whose executable lies under that build folder is a build-tree
// program and reads the source tree's stdlib/.
#ifndef PLANT_STDLIB_DIR
#define PLANT_STDLIB_DIR ""
#endif
#ifndef PLANT_BUILD_DIR
#define PLANT_BUILD_DIR ""
#endif

namespace plant {

namespace fs = std::filesystem;

namespace {

// Whether `p` is `root` or lies under it, component by component: /a/bc is not under /a/b.
bool under(const fs::path& root, const fs::path& p) {
    auto [r, q] = std::mismatch(root.begin(), root.end(), p.begin(), p.end());
    return r == root.end() || (std::next(r) == root.end() && r->empty());
}

// The folder of the running executable, symbolic links resolved; empty when the system does not
// say (Linux tells through /proc/self/exe).
fs::path executable_dir() {
    std::error_code ec;
    fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    return ec ? fs::path() : exe.parent_path();
}

std::string find_standard_library() {
    std::error_code ec;
    const fs::path exe_dir = executable_dir();
    // an installed program: PREFIX/bin/plant reads PREFIX/share/plant/stdlib, wherever PREFIX is
    const fs::path installed = exe_dir.empty() ? fs::path() : (exe_dir.parent_path() / "share/plant/stdlib");
    if (!installed.empty() && fs::is_directory(installed, ec)) return installed.string();
    // a program in the build tree it was built in (build/plant, the tests, the benchmarks)
    const std::string build = PLANT_BUILD_DIR, source = PLANT_STDLIB_DIR;
    if (!exe_dir.empty() && !build.empty() && !source.empty()) {
        const fs::path build_id = fs::canonical(build, ec);
        if (!ec && under(build_id, exe_dir) && fs::is_directory(source, ec)) return source;
    }
    // none: name where an installed program would look, for the message of a failed import
    return installed.string();
}

} // namespace

const std::string& standard_library_dir() {
    static const std::string dir = find_standard_library();
    return dir;
}

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
    if (!standard_library_dir().empty()) dirs.push_back(standard_library_dir());
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
    return std::any_of(roots_.begin(), roots_.end(), [&](const fs::path& root) { return under(root, p); });
}

std::string FileAccess::refusal(const std::string& written) {
    return fmt::format("'{}' is outside the folders this grammar may read (its own folder, -I and "
                       "PLANT_PATH folders, the standard library); to allow it, pass --allow-read with "
                       "its folder",
                       written);
}

} // namespace plant
