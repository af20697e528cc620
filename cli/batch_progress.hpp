// What a batch says on stderr while it runs: the lines of failing variants and of print(...) in
// hooks, and on a terminal a progress bar with the rate and an estimate of the time left.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace plant::cli {

class Progress {
  public:
    Progress(std::uint64_t total, bool terminal);
    void done(bool ok);                  // a variant finished (thread-safe)
    void print(const std::string& line); // a line above the bar (thread-safe)
    void draw();                         // redraws the bar on a terminal
    // Clears the bar and prints how many variants ran, how fast, and how many failed.
    void finish(bool interrupted);
    std::uint64_t failed() const { return failed_.load(); }

  private:
    std::string bar(double seconds) const;

    std::mutex mutex_;
    const std::uint64_t total_;
    const bool terminal_;
    std::atomic<std::uint64_t> done_{0}, failed_{0};
    const std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
    bool drawn_ = false; // the bar is on the screen
};

} // namespace plant::cli
