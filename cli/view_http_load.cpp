// Finding and loading plant view's HTTP server module (view_http.hpp): PREFIX/lib/plant/ beside an
// installed PREFIX/bin/plant, else the program's own folder (build/plant beside
// build/plant-view-server.so). Only `plant view` calls this; no other command loads the module.
#include "view_http.hpp"

#include "plant/diagnostics.hpp"

#include <fmt/format.h>

#include <dlfcn.h>
#include <filesystem>
#include <system_error>

namespace plant::view_http {

namespace fs = std::filesystem;

ServeFunction load_view_server(std::string& error, bool& missing) {
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    missing = true;
    if (ec) {
        error = "plant: cannot tell where this program is (/proc/self/exe), so cannot find its HTTP "
                "server module " +
                std::string(kViewServerModule) + " (docs/install.md)";
        return nullptr;
    }
    const fs::path dir = exe.parent_path();
    const fs::path candidates[] = {dir.parent_path() / "lib/plant" / kViewServerModule,
                                   dir / kViewServerModule};
    for (const fs::path& path : candidates) {
        if (!fs::is_regular_file(path, ec)) continue;
        missing = false;
        // RTLD_LOCAL: the module's libraries serve only the module
        void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
        if (!handle) {
            const char* why = dlerror();
            error = fmt::format("plant: cannot load plant view's HTTP server module '{}': {}",
                                escape_controls(path.string()), escape_controls(why ? why : "unknown error"));
            return nullptr;
        }
        void* entry = dlsym(handle, kViewServeSymbol);
        if (!entry) {
            error = fmt::format("plant: '{}' is not this plant's HTTP server module (it has no {}): "
                                "install the module built with this program (docs/install.md)",
                                escape_controls(path.string()), kViewServeSymbol);
            return nullptr; // the handle stays open: unloading a half-checked library gains nothing
        }
        return reinterpret_cast<ServeFunction>(entry);
    }
    error = fmt::format("plant: plant view needs its HTTP server module, which is missing: looked for "
                        "'{}' and '{}' (install plant with it, or build it: docs/install.md)",
                        escape_controls(candidates[0].string()), escape_controls(candidates[1].string()));
    return nullptr;
}

} // namespace plant::view_http
