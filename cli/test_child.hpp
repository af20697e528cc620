// The child processes plant test starts (docs/testing.md "Time limits and signals"): each runs in
// a process group of its own, under a time limit, and is killed with plant test when a signal
// (SIGINT, SIGTERM, SIGHUP) stops plant test.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace plant::cli {

struct ChildOutcome {
    int exit_code = -1;
    std::string out, err;
    bool timed_out = false;
};

// Runs this program with `args` in directory `dir` for at most `seconds`, capturing standard
// output and error; past the limit the child's process group is stopped (SIGTERM, then SIGKILL a
// second later) and `timed_out` set.
ChildOutcome run_child(const std::vector<std::string>& args, const std::filesystem::path& dir,
                       double seconds);

// While one lives, SIGINT, SIGTERM and SIGHUP stop the running child's process group and are
// recorded instead of ending plant test at once; `pending()` names the signal, and the
// destructor, when one came, ends plant test by it (after the caller's clean-up ran).
class ChildSignalGuard {
  public:
    ChildSignalGuard();
    ~ChildSignalGuard();
    ChildSignalGuard(const ChildSignalGuard&) = delete;
    ChildSignalGuard& operator=(const ChildSignalGuard&) = delete;
    static int pending();
};

} // namespace plant::cli
