// plant test's children: spawned in a process group of their own, waited for under a time
// limit, and taken down with plant test when it is stopped by a signal, so that no child outlives
// it (reparented to init and still running).
#include "test_child.hpp"

#include "plant/compiler.hpp"

#include <chrono>
#include <csignal>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

extern char** environ;

namespace plant::cli {

namespace fs = std::filesystem;

namespace {

volatile std::sig_atomic_t g_signal = 0;
volatile pid_t g_child_group = 0; // the running child's process group, 0 when none

// async-signal-safe: kill() and assignments to sig_atomic_t (signal-safety(7))
void on_signal(int sig) {
    g_signal = sig;
    if (g_child_group > 0) kill(-g_child_group, SIGTERM);
}

struct sigaction g_old[3];
constexpr int kSignals[3] = {SIGINT, SIGTERM, SIGHUP};

std::string slurp(const char* path) {
    std::string s;
    read_file(path, s);
    return s;
}

// Waits for `pid` until `deadline`; returns its wait status, or -1 when the deadline passed.
int wait_until(pid_t pid, std::chrono::steady_clock::time_point deadline) {
    auto pause = std::chrono::microseconds(200);
    for (;;) {
        int status = 0;
        const pid_t r = waitpid(pid, &status, WNOHANG);
        if (r == pid) return status;
        if (r < 0 && errno != EINTR) return 0;
        const auto now = std::chrono::steady_clock::now();
        if (g_signal && deadline - now > std::chrono::seconds(1)) deadline = now + std::chrono::seconds(1);
        if (now >= deadline) return -1;
        std::this_thread::sleep_for(pause);
        pause = std::min(pause * 2, std::chrono::microseconds(20000));
    }
}

} // namespace

ChildSignalGuard::ChildSignalGuard() {
    struct sigaction sa {};
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    for (int k = 0; k < 3; ++k) {
        sigaction(kSignals[k], nullptr, &g_old[k]);
        // a signal ignored when plant test started (nohup, a shell's background job) stays so
        if ((g_old[k].sa_flags & SA_SIGINFO) || g_old[k].sa_handler != SIG_IGN)
            sigaction(kSignals[k], &sa, nullptr);
    }
}

ChildSignalGuard::~ChildSignalGuard() {
    for (int k = 0; k < 3; ++k) sigaction(kSignals[k], &g_old[k], nullptr);
    if (const int sig = g_signal) {
        std::signal(sig, SIG_DFL);
        std::raise(sig);
    }
}

int ChildSignalGuard::pending() {
    return g_signal;
}

ChildOutcome run_child(const std::vector<std::string>& args, const fs::path& dir, double seconds) {
    ChildOutcome o;
    if (g_signal) return o;
    char out_name[] = "/tmp/plant-test-out-XXXXXX";
    char err_name[] = "/tmp/plant-test-err-XXXXXX";
    int out_fd = mkstemp(out_name);
    int err_fd = mkstemp(err_name);
    if (out_fd < 0 || err_fd < 0) {
        o.err = "cannot create temporary files";
        return o;
    }
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_adddup2(&fa, out_fd, 1);
    posix_spawn_file_actions_adddup2(&fa, err_fd, 2);
    posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
    if (!dir.empty()) posix_spawn_file_actions_addchdir_np(&fa, dir.c_str());
    // a process group of its own, so that a timeout or a signal stops it and whatever it started
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF);
    posix_spawnattr_setpgroup(&attr, 0);
    sigset_t defaults;
    sigemptyset(&defaults);
    for (int sig : kSignals) sigaddset(&defaults, sig);
    posix_spawnattr_setsigdefault(&attr, &defaults);
    std::vector<char*> argv;
    static const std::string self = fs::read_symlink("/proc/self/exe").string();
    std::string argv0 = self;
    argv.push_back(argv0.data());
    std::vector<std::string> copy = args;
    for (auto& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    // children print without colour and see the same environment
    setenv("NO_COLOR", "1", 1);
    pid_t pid = 0;
    if (posix_spawn(&pid, self.c_str(), &fa, &attr, argv.data(), environ) == 0) {
        g_child_group = pid;
        if (g_signal) kill(-pid, SIGTERM); // a signal that came between the spawn and here
        const auto limit = std::chrono::duration<double>(seconds);
        int status =
            wait_until(pid, std::chrono::steady_clock::now() +
                                std::chrono::duration_cast<std::chrono::steady_clock::duration>(limit));
        if (status == -1) {
            o.timed_out = !g_signal;
            kill(-pid, SIGTERM);
            status = wait_until(pid, std::chrono::steady_clock::now() + std::chrono::seconds(1));
        }
        if (status == -1) {
            kill(-pid, SIGKILL);
            status = wait_until(pid, std::chrono::steady_clock::time_point::max());
        }
        g_child_group = 0;
        o.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    }
    posix_spawnattr_destroy(&attr);
    posix_spawn_file_actions_destroy(&fa);
    close(out_fd);
    close(err_fd);
    o.out = slurp(out_name);
    o.err = slurp(err_name);
    unlink(out_name);
    unlink(err_name);
    return o;
}

} // namespace plant::cli
