// plant view's watcher: inotify(7) on the folders of every file the grammar read. Folders rather
// than files, as many editors save by writing a new file and renaming it over the old one.
#include "cmd_view.hpp"

#include <filesystem>
#include <map>
#include <poll.h>
#include <sys/inotify.h>
#include <unistd.h>

namespace plant::cli {

namespace fs = std::filesystem;

namespace {

// The folders watched, by watch descriptor, and the file names in each that matter.
struct Watches {
    int fd = -1;
    std::map<int, std::string> folders;      // wd -> folder
    std::set<std::string> files;             // absolute paths
    std::map<std::string, int> folder_watch; // folder -> wd

    void update(const std::set<std::string>& wanted) {
        files = wanted;
        for (const auto& f : wanted) {
            const std::string folder = fs::path(f).parent_path().string();
            if (folder_watch.count(folder)) continue;
            const int wd = inotify_add_watch(
                fd, folder.c_str(), IN_CLOSE_WRITE | IN_MOVED_TO | IN_CREATE | IN_DELETE | IN_MODIFY);
            if (wd < 0) continue; // a folder that went away: its files are missing, the compiler says so
            folder_watch[folder] = wd;
            folders[wd] = folder;
        }
    }

    // Reads the pending events; true when one names a watched file.
    bool read_events() {
        alignas(inotify_event) char buffer[16384];
        bool relevant = false;
        for (;;) {
            const ssize_t n = read(fd, buffer, sizeof buffer);
            if (n <= 0) break;
            for (ssize_t at = 0; at < n;) {
                const auto* e = reinterpret_cast<const inotify_event*>(buffer + at);
                at += static_cast<ssize_t>(sizeof(inotify_event) + e->len);
                auto it = folders.find(e->wd);
                if (it == folders.end() || e->len == 0) continue;
                if (files.count((fs::path(it->second) / e->name).string())) relevant = true;
            }
        }
        return relevant;
    }
};

bool wait_readable(int fd, int ms) {
    pollfd p{fd, POLLIN, 0};
    return poll(&p, 1, ms) > 0 && (p.revents & POLLIN);
}

} // namespace

void watch_files(ViewModel& model, ViewEvents& events, const std::atomic<bool>& stop) {
    Watches w;
    w.fd = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
    if (w.fd < 0) return;
    w.update(model.watched_files());
    while (!stop) {
        if (!wait_readable(w.fd, 200) || !w.read_events()) continue;
        // a save is often several events (truncate, write, close; or write and rename): let the
        // burst settle for a few milliseconds, then derive once
        while (wait_readable(w.fd, 15)) w.read_events();
        events.publish(model.rebuild());
        w.update(model.watched_files());
    }
    close(w.fd);
}

} // namespace plant::cli
