// What `plant run` says on stderr while it works, when stderr is a terminal: each step with its
// modules, the rate and an estimate of the time the remaining steps take, then interpreting,
// meshing (with the triangles and bytes estimated beforehand) and writing each file. One line,
// rewritten in place and cleared at the end.
#pragma once

#include "plant/derive.hpp"

#include <string>

namespace plant::cli {

class RunProgress {
  public:
    explicit RunProgress(bool terminal) : terminal_(terminal) {}
    bool enabled() const { return terminal_; }
    // After step s.step of `target`.
    void step(const StepStats& s, int target);
    // A stage after the derivation: "meshing about 1.2 million triangles (96 MB)".
    void stage(const std::string& what);
    void clear();

  private:
    void show(const std::string& line);
    bool terminal_;
    std::size_t last_modules_ = 0, prev_modules_ = 0; // the strings of the last two steps
};

// "1.2 million", "340 thousand", "812": counts for people.
std::string human_count(double n);
// "1.2 GB", "96 MB", "12 kB".
std::string human_bytes(double bytes);
// The time the steps from `done` + 1 to `target` are expected to take, in ms: a step's time
// follows its string, and the string grows each step by the ratio of the last two strings
// (between 1 and 16 times), as an L-system's does. (From the strings, not the steps' times: the
// time of a step of a few thousand modules is noise, and its ratio made estimates of years.)
double remaining_ms(double last_ms, std::size_t last_modules, std::size_t prev_modules, int done, int target);

} // namespace plant::cli
