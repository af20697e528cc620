// plant view FILE: serves the plant to a browser on 127.0.0.1 and derives it again whenever the
// grammar or a file it reads is saved, or the page changes a param or the seed (docs/view.md).
#include "cmd_view.hpp"

#include <fmt/format.h>

#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <iostream>
#include <pthread.h>
#include <spawn.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

extern char** environ;

namespace plant::cli {

namespace {

struct ViewCmd {
    GrammarOptions g;
    int port = 8765;
    bool open = false;
    int sides = 8;
    bool no_obstacles = false;
};

// Starts the desktop's browser on the URL (xdg-open), without a shell and without waiting.
void open_browser(const std::string& url) {
    pid_t pid = 0;
    const char* argv[] = {"xdg-open", url.c_str(), nullptr};
    if (posix_spawnp(&pid, "xdg-open", nullptr, nullptr, const_cast<char* const*>(argv), environ) != 0) {
        std::cerr << "plant: could not run xdg-open; open " << url << " yourself\n";
        return;
    }
    std::thread([pid] { waitpid(pid, nullptr, 0); }).detach(); // reaped, not left a zombie
}

// SIGINT and SIGTERM are taken by one thread (sigwait) that stops the server; every other thread
// has them blocked, so none is interrupted halfway through a derivation or a write.
class Signals {
  public:
    Signals() {
        sigemptyset(&set_);
        sigaddset(&set_, SIGINT);
        sigaddset(&set_, SIGTERM);
        sigaddset(&set_, SIGUSR1); // sent by the destructor to end the waiting thread
        pthread_sigmask(SIG_BLOCK, &set_, nullptr);
    }
    void start(std::function<void()> on_signal) {
        thread_ = std::thread([this, on_signal] {
            int sig = 0;
            sigwait(&set_, &sig);
            if (sig != SIGUSR1) on_signal();
        });
    }
    ~Signals() {
        if (thread_.joinable()) {
            pthread_kill(thread_.native_handle(), SIGUSR1);
            thread_.join();
        }
        pthread_sigmask(SIG_UNBLOCK, &set_, nullptr);
    }

  private:
    sigset_t set_;
    std::thread thread_;
};

int view_main(ViewCmd& c) {
    if (kViewThreeVersion[0] == '\0') {
        std::cerr << "plant: this plant was built without three.js, which the page needs: run "
                     "viewer/install.sh (npm ci of the pinned three) or scripts/install-deps, then "
                     "build plant again (docs/view.md)\n";
        return kRuntime;
    }
    if (reads_standard_input(c.g)) {
        std::cerr << "plant: plant view watches its grammar's file and grows it again when it is saved, so "
                     "it needs a file: save the grammar and name it\n";
        return kUsage;
    }
    if (std::error_code ec; !std::filesystem::is_regular_file(c.g.file, ec)) {
        std::error_code ec2;
        const std::string why = ec && ec != std::errc::no_such_file_or_directory ? ec.message()
                                : std::filesystem::is_directory(c.g.file, ec2)   ? "it is a directory"
                                : std::filesystem::exists(c.g.file, ec2)         ? "it is not a regular file"
                                                                                 : "no such file";
        std::cerr << fmt::format("plant: cannot read '{}': {}\n", escape_controls(c.g.file), why);
        return kNoInput;
    }
    // the HTTP server module, before any work: only `plant view` loads it (view_http.hpp)
    std::string why;
    bool missing = false;
    const view_http::ServeFunction serve = view_http::load_view_server(why, missing);
    if (!serve) {
        std::cerr << why << "\n";
        return missing ? kNoInput : kRuntime;
    }
    // the scratch folder the GLB export writes into, under $TMPDIR (else /tmp)
    const char* tmpdir = std::getenv("TMPDIR");
    std::string scratch = std::string(tmpdir && *tmpdir ? tmpdir : "/tmp") + "/plant-view-XXXXXX";
    if (!mkdtemp(scratch.data())) {
        std::cerr << fmt::format("plant: cannot create a scratch folder in '{}'\n",
                                 escape_controls(tmpdir && *tmpdir ? tmpdir : "/tmp"));
        return kCantCreate;
    }
    OutputOptions oo;
    oo.sides = c.sides;
    oo.obstacles = !c.no_obstacles;
    Signals signals; // before any thread starts, so that all inherit the mask
    ViewModel model(c.g, oo, scratch);
    ViewEvents events;
    std::atomic<bool> stop{false};
    std::mutex stopper_mutex;
    std::function<void()> stopper;
    signals.start([&] {
        stop = true;
        events.stop();
        std::lock_guard lock(stopper_mutex);
        if (stopper) stopper();
    });
    events.publish(model.rebuild());
    std::thread watcher([&] { watch_files(model, events, stop); });
    ViewServerOptions so;
    so.port = c.port;
    so.on_listening = [&](int port) {
        const std::string url = fmt::format("http://127.0.0.1:{}/", port);
        std::cout << "plant view: " << url << "  (Ctrl-C stops)" << std::endl;
        if (c.open) open_browser(url);
    };
    const int port = serve_view(serve, model, events, so, [&](std::function<void()> f) {
        std::lock_guard lock(stopper_mutex);
        stopper = std::move(f);
        if (stopper && stop) stopper(); // a signal came before the server was up
    });
    stop = true;
    events.stop();
    watcher.join();
    std::error_code ec;
    std::filesystem::remove_all(scratch, ec);
    if (port < 0) {
        std::cerr << fmt::format("plant: cannot listen on 127.0.0.1:{} (in use?): try another --port, or "
                                 "--port 0 for any free one\n",
                                 c.port);
        return kRuntime;
    }
    return kOk;
}

} // namespace

void setup_view(CLI::App& app, int& exit_code) {
    auto c = std::make_shared<ViewCmd>();
    auto* cmd = app.add_subcommand(
        "view", "Show the plant live in a web browser: redrawn on every save, with params, seed and steps "
                "as controls (docs/view.md)");
    add_grammar_options(*cmd, c->g, true);
    cmd->get_option("FILE")->description("The .plant grammar, a file (watched: saving it redraws the plant)");
    cmd->add_option("--port", c->port, "The port on 127.0.0.1 to serve on (0: any free port)")
        ->transform(number_in(0, 65535, Bound::Whole))
        ->capture_default_str();
    cmd->add_flag("--open", c->open, "Open the page in the desktop's browser (xdg-open)");
    cmd->add_option("--sides", c->sides, "Sides of each tube's cross-section")
        ->transform(number_in(3, 64, Bound::Whole))
        ->capture_default_str();
    cmd->add_flag("--no-obstacles", c->no_obstacles, "Leave the environments' walls and boxes out");
    cmd->callback([c, &exit_code] {
        set_memory_budget(c->g.max_memory);
        exit_code = view_main(*c);
    });
}

} // namespace plant::cli
