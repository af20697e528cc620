#include "run_progress.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iostream>

namespace plant::cli {

std::string human_count(double n) {
    if (n >= 1e9) return fmt::format("{:.1f} billion", n / 1e9);
    if (n >= 1e6) return fmt::format("{:.1f} million", n / 1e6);
    if (n >= 1e4) return fmt::format("{:.0f} thousand", n / 1e3);
    return fmt::format("{:.0f}", n);
}

std::string human_bytes(double bytes) {
    if (bytes >= 1e9) return fmt::format("{:.1f} GB", bytes / 1e9);
    if (bytes >= 1e6) return fmt::format("{:.0f} MB", bytes / 1e6);
    return fmt::format("{:.0f} kB", std::ceil(bytes / 1e3));
}

double remaining_ms(double last_ms, std::size_t last_modules, std::size_t prev_modules, int done,
                    int target) {
    const double growth =
        prev_modules > 0 ? std::clamp(double(last_modules) / double(prev_modules), 1.0, 16.0) : 1.0;
    double total = 0, t = last_ms;
    for (int k = done + 1; k <= target && total < 1e12; ++k) total += (t *= growth);
    return total;
}

void RunProgress::show(const std::string& line) {
    if (terminal_) std::cerr << "\r\x1b[K" << line << std::flush;
}

void RunProgress::step(const StepStats& s, int target) {
    prev_modules_ = last_modules_;
    last_modules_ = s.modules;
    if (!terminal_) return;
    const double rate = s.ms > 0 ? double(s.modules) / (s.ms / 1000.0) : 0.0;
    std::string line = fmt::format("step {}/{}: {} modules, {} modules/s", s.step, target,
                                   human_count(double(s.modules)), human_count(rate));
    // once a step's time follows its string: a step of a few thousand modules takes what the
    // step itself costs, and the estimate from it was minutes for a run of a second
    if (s.step < target && s.step >= 2 && s.modules >= 100000)
        line += fmt::format(", about {:.0f} s left",
                            remaining_ms(s.ms, last_modules_, prev_modules_, s.step, target) / 1000.0);
    show(line);
}

void RunProgress::stage(const std::string& what) {
    show(what);
}

void RunProgress::clear() {
    if (terminal_) std::cerr << "\r\x1b[K" << std::flush;
}

} // namespace plant::cli
