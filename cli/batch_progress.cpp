#include "batch_progress.hpp"

#include <fmt/format.h>

#include <cmath>
#include <iostream>

namespace plant::cli {

namespace {

std::string clock_text(double seconds) {
    const auto s = static_cast<long long>(std::lround(seconds));
    return s >= 3600 ? fmt::format("{}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60)
                     : fmt::format("{}:{:02}", s / 60, s % 60);
}

} // namespace

Progress::Progress(std::uint64_t total, bool terminal) : total_(total), terminal_(terminal) {}

void Progress::done(bool ok) {
    if (!ok) failed_.fetch_add(1);
    done_.fetch_add(1);
}

void Progress::print(const std::string& line) {
    std::lock_guard lock(mutex_);
    if (drawn_) std::cerr << "\r\x1b[K";
    drawn_ = false;
    std::cerr << line << (line.empty() || line.back() != '\n' ? "\n" : "") << std::flush;
}

std::string Progress::bar(double seconds) const {
    constexpr int kWidth = 30;
    const std::uint64_t done = done_.load(), failed = failed_.load();
    const double part = total_ ? double(done) / double(total_) : 1.0;
    const int filled = static_cast<int>(part * kWidth);
    std::string out = fmt::format("[{}{}] {}/{}", std::string(filled, '#'), std::string(kWidth - filled, '.'),
                                  done, total_);
    if (done > 0 && seconds > 0) {
        const double rate = double(done) / seconds;
        out += fmt::format("  {:.1f}/s  ETA {}", rate, clock_text(double(total_ - done) / rate));
    }
    if (failed) out += fmt::format("  {} failed", failed);
    return out;
}

void Progress::draw() {
    if (!terminal_) return;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    std::lock_guard lock(mutex_);
    std::cerr << "\r" << bar(seconds) << "\x1b[K" << std::flush;
    drawn_ = true;
}

void Progress::finish(bool interrupted) {
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    std::lock_guard lock(mutex_);
    if (drawn_) std::cerr << "\r\x1b[K";
    drawn_ = false;
    const std::uint64_t done = done_.load(), failed = failed_.load();
    std::cerr << fmt::format("plant: {} of {} variants{} in {:.1f} s ({:.1f} a second){}\n", done, total_,
                             interrupted ? " (interrupted)" : "", seconds,
                             seconds > 0 ? double(done) / seconds : 0.0,
                             failed ? fmt::format(", {} failed", failed) : "");
}

} // namespace plant::cli
