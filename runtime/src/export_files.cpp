// What every writer shares: the atomic file writer, the mesh part checks, and the scene a writer
// draws (prototype scenes flattened).
#include "plant/export.hpp"

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <sys/stat.h>
#include <system_error>
#include <unistd.h>

namespace plant {

namespace fs = std::filesystem;

namespace {

std::string quoted(const std::string& s) {
    return "'" + s + "'";
}

// Creates a new, empty file beside `path` (same directory, hidden, unique name) and returns its
// path with `file` open for writing. Throws ExportError when the directory is not writable.
std::string create_temp_beside(const std::string& path, std::FILE*& file) {
    static std::atomic<unsigned> counter{0};
    const fs::path target(path);
    if (target.filename().empty()) throw ExportError("cannot write " + quoted(path) + ": not a file name");
    const fs::path dir = target.parent_path();
    for (int attempt = 0;; ++attempt) {
        const std::string name = "." + target.filename().string() + ".tmp-" + std::to_string(::getpid()) +
                                 "-" + std::to_string(counter++);
        const std::string temp = (dir / name).string();
        // "x": fail if the file exists, so two writers never share a temporary file.
        file = std::fopen(temp.c_str(), "wbx");
        if (file) return temp;
        const int err = errno;
        if (err == EEXIST && attempt < 100) continue;
        throw ExportError("cannot write " + quoted(path) + ": cannot create a file in " +
                          quoted(dir.empty() ? std::string(".") : dir.string()) + ": " + std::strerror(err));
    }
}

void remove_quietly(const std::string& temp) {
    std::error_code ignored;
    fs::remove(temp, ignored);
}

} // namespace

void check_mesh_part(const MeshPart& part, const std::string& what) {
    const std::size_t nv = part.positions.size();
    if (!part.normals.empty() && part.normals.size() != nv)
        throw ExportError(what + " has " + std::to_string(nv) + " positions but " +
                          std::to_string(part.normals.size()) + " normals");
    if (!part.uvs.empty() && part.uvs.size() != nv)
        throw ExportError(what + " has " + std::to_string(nv) + " positions but " +
                          std::to_string(part.uvs.size()) + " texture coordinates");
    if (part.indices.size() % 3 != 0)
        throw ExportError(what + " has an index count (" + std::to_string(part.indices.size()) +
                          ") that is not a multiple of 3");
    // the largest index first (a loop the compiler vectorizes), the offending one only past it
    std::uint32_t top = 0;
    for (std::uint32_t i : part.indices) top = i > top ? i : top;
    if (part.indices.empty() || top < nv) return;
    for (std::uint32_t i : part.indices)
        if (i >= nv)
            throw ExportError(what + " has index " + std::to_string(i) + " but only " + std::to_string(nv) +
                              " vertices");
}

const Scene& exported_scene(const Scene& scene, Scene& storage, const std::string& what) {
    const Scene* s = &scene;
    if (scene.nested()) {
        try {
            storage = flatten_keeping_bounds(scene); // the writers do not read the bounds
        } catch (const std::out_of_range& e) {
            throw ExportError(what + ": " + e.what());
        }
        s = &storage;
    }
    for (const Instance& inst : s->instances)
        if (inst.prototype >= s->prototypes.size())
            throw ExportError(what + ": an instance places prototype " + std::to_string(inst.prototype) +
                              " but the scene has " + std::to_string(s->prototypes.size()));
    return *s;
}

int replace_file(const char* temp, const char* target) {
#ifdef RENAME_EXCHANGE
    struct stat st {};
    if (::lstat(target, &st) == 0 && S_ISREG(st.st_mode)) {
        if (::renameat2(AT_FDCWD, temp, AT_FDCWD, target, RENAME_EXCHANGE) == 0) {
            // `temp` now names the old contents (a signal handler may have removed it already)
            if (::unlink(temp) != 0 && errno != ENOENT) return errno;
            return 0;
        }
        if (errno != EINVAL && errno != ENOSYS && errno != EOPNOTSUPP && errno != ENOENT) return errno;
    }
#endif
    return ::rename(temp, target) == 0 ? 0 : errno;
}

void write_file_atomically(const std::string& path, const std::string& bytes) {
    std::FILE* file = nullptr;
    const std::string temp = create_temp_beside(path, file);
    const std::size_t written = bytes.empty() ? 0 : std::fwrite(bytes.data(), 1, bytes.size(), file);
    int err = written == bytes.size() ? 0 : errno;
    if (std::fflush(file) != 0 && err == 0) err = errno;
    if (std::fclose(file) != 0 && err == 0) err = errno;
    if (written != bytes.size() && err == 0) err = EIO;
    if (err != 0) {
        remove_quietly(temp);
        throw ExportError("cannot write " + quoted(path) + ": " + std::strerror(err));
    }
    if (const int e = replace_file(temp.c_str(), path.c_str()); e != 0) {
        remove_quietly(temp);
        throw ExportError("cannot write " + quoted(path) + ": " + std::strerror(e));
    }
}

} // namespace plant
