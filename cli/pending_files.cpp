#include "pending_files.hpp"

#include "plant/export.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <iterator>
#include <sys/stat.h>
#include <unistd.h>

namespace plant::cli {

namespace fs = std::filesystem;

namespace {

// What the signal handler reads: published before the handlers are installed, withdrawn after
// they are put back, never changed in between but for the `live` flags and the count of folders
// made (the folders' array is reserved whole beforehand). The handler only calls unlink, rmdir,
// sigaction and raise, which are async-signal-safe (signal-safety(7)).
struct Registry {
    const std::string* temps = nullptr;
    const std::atomic<bool>* live = nullptr;
    std::size_t count = 0;
    const std::string* dirs = nullptr; // the folders made, outermost first
    const std::atomic<std::size_t>* dir_count = nullptr;
    struct sigaction old_int {
    }, old_term{}, old_hup{}; // SIGHUP (the terminal closed) is handled as SIGTERM
};
std::atomic<Registry*> g_registry{nullptr};
std::atomic<const std::atomic<bool>*> g_shared_stop{nullptr}; // share_signals()

void on_signal(int sig, siginfo_t* info, void* context) {
    Registry* r = g_registry.load();
    if (!r) return;
    const struct sigaction& old = sig == SIGINT ? r->old_int : sig == SIGHUP ? r->old_hup : r->old_term;
    if (!(old.sa_flags & SA_SIGINFO) && old.sa_handler == SIG_IGN) return;
    if ((old.sa_flags & SA_SIGINFO) && old.sa_sigaction) {
        old.sa_sigaction(sig, info, context);
        return;
    }
    if (!(old.sa_flags & SA_SIGINFO) && old.sa_handler != SIG_DFL) {
        old.sa_handler(sig);
        return;
    }
    for (std::size_t k = 0; k < r->count; ++k)
        if (r->live[k].load()) ::unlink(r->temps[k].c_str());
    // rmdir removes only empty folders: one holding a file renamed into place, or anything else, stays
    for (std::size_t k = r->dir_count->load(std::memory_order_acquire); k > 0; --k)
        ::rmdir(r->dirs[k - 1].c_str());
    // end the process by the signal, as it would have ended without this handler
    struct sigaction dfl {};
    dfl.sa_handler = SIG_DFL;
    sigemptyset(&dfl.sa_mask);
    sigaction(sig, &dfl, nullptr);
    raise(sig); // delivered when this handler returns (the signal is blocked while it runs)
}

std::string in_quotes(const std::string& s) {
    return "'" + s + "'";
}

} // namespace

PendingFiles::PendingFiles(const std::vector<std::string>& targets)
    : targets_(targets), live_(std::make_unique<std::atomic<bool>[]>(targets.size())) {
    static std::atomic<unsigned> counter{0};
    for (const auto& t : targets_) {
        const fs::path target(t);
        temps_.push_back(
            (target.parent_path() / ("." + target.filename().string() + ".plant-tmp-" +
                                     std::to_string(::getpid()) + "-" + std::to_string(counter++)))
                .string());
    }
    // room for every folder on the way to every target, so that adding one never moves the others
    std::size_t room = 0;
    for (const auto& t : targets_) {
        const fs::path parent = fs::path(t).parent_path();
        room += static_cast<std::size_t>(std::distance(parent.begin(), parent.end()));
    }
    made_dirs_.reserve(room);
    if (g_shared_stop.load()) return; // a batch: its own handlers stop it
    owns_signals_ = true;
    auto* r =
        new Registry{temps_.data(), live_.get(), temps_.size(), made_dirs_.data(), &made_count_, {}, {}, {}};
    struct sigaction sa {};
    sa.sa_sigaction = on_signal;
    sa.sa_flags = SA_SIGINFO;
    sigemptyset(&sa.sa_mask);
    sigaddset(&sa.sa_mask, SIGINT);
    sigaddset(&sa.sa_mask, SIGTERM);
    sigaddset(&sa.sa_mask, SIGHUP);
    // the old actions are read before the registry is published, so the handler always has them
    sigaction(SIGINT, nullptr, &r->old_int);
    sigaction(SIGTERM, nullptr, &r->old_term);
    sigaction(SIGHUP, nullptr, &r->old_hup);
    g_registry.store(r);
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
    sigaction(SIGHUP, &sa, nullptr);
}

PendingFiles::~PendingFiles() {
    Registry* r = owns_signals_ ? g_registry.load() : nullptr;
    if (r) {
        sigaction(SIGINT, &r->old_int, nullptr);
        sigaction(SIGTERM, &r->old_term, nullptr);
        sigaction(SIGHUP, &r->old_hup, nullptr);
        g_registry.store(nullptr);
        delete r;
    }
    for (std::size_t k = 0; k < temps_.size(); ++k)
        if (live_[k].load()) ::unlink(temps_[k].c_str());
    // folders made for the outputs of a run that failed go too, deepest first (rmdir removes
    // only empty ones: whatever else was put in them meanwhile stays)
    if (!committed_)
        for (auto d = made_dirs_.rbegin(); d != made_dirs_.rend(); ++d) ::rmdir(d->c_str());
}

namespace {

// Writes all of `size` bytes to `fd`; 0, or the error number.
int write_all(int fd, const char* data, std::size_t size) {
    while (size > 0) {
        const ssize_t n = ::write(fd, data, size);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return n < 0 ? errno : EIO;
        data += n;
        size -= static_cast<std::size_t>(n);
    }
    return 0;
}

} // namespace

std::string output_problem(const std::string& target) {
    const fs::path path(target);
    if (path.filename().empty()) return "cannot write " + in_quotes(target) + ": not a file name";
    std::error_code ec;
    if (fs::is_directory(path, ec)) return "cannot write " + in_quotes(target) + ": it is a folder";
    fs::path dir = path.parent_path();
    while (!dir.empty() && !fs::exists(fs::symlink_status(dir, ec)) && dir != dir.parent_path())
        dir = dir.parent_path();
    const std::string shown = dir.empty() ? std::string(".") : dir.string();
    auto problem = [&](int err) {
        return fmt::format("cannot write {}: cannot create a file in {}: {}", in_quotes(target),
                           in_quotes(shown), std::strerror(err));
    };
    if (!fs::is_directory(shown, ec)) return problem(ENOTDIR);
#ifdef O_TMPFILE
    const int fd = ::open(shown.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0600);
    if (fd >= 0) {
        ::close(fd);
        return {};
    }
    // a file system without unnamed files says so; the permissions then tell
    if (errno != EOPNOTSUPP && errno != EISDIR && errno != EINVAL) return problem(errno);
#endif
    return ::access(shown.c_str(), W_OK | X_OK) == 0 ? std::string() : problem(errno);
}

void PendingFiles::write(std::size_t k, const std::string& bytes) {
    write_with(k, [&](const ByteSink& sink) { sink(bytes.data(), bytes.size()); });
}

void PendingFiles::write_with(std::size_t k, const std::function<void(const ByteSink&)>& produce) {
    const std::string& target = targets_[k];
    const fs::path parent = fs::path(target).parent_path();
    if (fs::path(target).filename().empty())
        throw ExportError("cannot write " + in_quotes(target) + ": not a file name");
    std::error_code ec;
    if (!parent.empty()) {
        // the folders on the way that do not exist yet are made here, outermost first, and only
        // those this call made are remembered (a path through '..' names folders that exist, and
        // one made meanwhile by another process is not ours to remove)
        std::vector<fs::path> missing;
        for (fs::path d = parent; !d.empty() && !fs::exists(fs::symlink_status(d, ec)); d = d.parent_path()) {
            missing.push_back(d);
            if (d == d.parent_path()) break;
        }
        for (auto d = missing.rbegin(); d != missing.rend(); ++d)
            if (::mkdir(d->c_str(), 0777) == 0 && made_dirs_.size() < made_dirs_.capacity()) {
                made_dirs_.push_back(d->string());
                made_count_.store(made_dirs_.size(), std::memory_order_release);
            }
    }
    live_[k].store(true); // before the file exists: a signal from here on removes it
    const int fd = ::open(temps_[k].c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0) {
        const int err = errno;
        live_[k].store(false);
        throw ExportError(fmt::format("cannot write {}: cannot create a file in {}: {}", in_quotes(target),
                                      in_quotes(parent.empty() ? std::string(".") : parent.string()),
                                      std::strerror(err)));
    }
    // small pieces are gathered in `staged`; large ones go straight to the file
    constexpr std::size_t kStage = 64 * 1024;
    std::string staged;
    staged.reserve(kStage);
    int err = 0;
    const ByteSink sink = [&](const void* data, std::size_t size) {
        if (err != 0) return;
        const auto* p = static_cast<const char*>(data);
        if (staged.size() + size <= kStage) {
            staged.append(p, size);
            return;
        }
        if ((err = write_all(fd, staged.data(), staged.size())) != 0) return;
        staged.clear();
        if (size < kStage)
            staged.append(p, size);
        else
            err = write_all(fd, p, size);
    };
    try {
        produce(sink);
    } catch (...) {
        ::close(fd);
        throw;
    }
    if (err == 0) err = write_all(fd, staged.data(), staged.size());
    if (::close(fd) != 0 && err == 0) err = errno;
    if (err != 0) throw ExportError("cannot write " + in_quotes(target) + ": " + std::strerror(err));
}

void PendingFiles::share_signals(const std::atomic<bool>* stop) {
    g_shared_stop.store(stop);
}

void PendingFiles::commit() {
    if (const std::atomic<bool>* stop = g_shared_stop.load(); stop && stop->load())
        throw ExportError("interrupted");
    // a rename onto a folder fails: find it before any file is renamed
    for (const auto& t : targets_) {
        struct stat st {};
        if (::stat(t.c_str(), &st) == 0 && S_ISDIR(st.st_mode))
            throw ExportError("cannot write " + in_quotes(t) + ": it is a folder");
    }
    for (std::size_t k = 0; k < temps_.size(); ++k) {
        if (const int e = replace_file(temps_[k].c_str(), targets_[k].c_str()); e != 0)
            throw ExportError("cannot write " + in_quotes(targets_[k]) + ": " + std::strerror(e));
        live_[k].store(false);
    }
    committed_ = true;
}

} // namespace plant::cli
