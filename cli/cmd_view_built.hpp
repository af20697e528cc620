// plant view's model as the files that serve it read it: a compiled program and its kept steps.
#pragma once

#include "cmd_view.hpp"

#include "plant/environment_phase.hpp"

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace plant::cli {

// A compiled program and its derivation at every kept step (index: the step number; null when
// that step was not kept).
struct ViewModel::Built {
    std::unique_ptr<SourceManager> sources;
    std::unique_ptr<Program> program;
    std::unique_ptr<TurtleEnvironmentPhase> phase;
    std::vector<std::unique_ptr<Derivation>> steps;
    std::vector<std::size_t> modules;                         // per step
    std::map<int, std::string> glb;                           // exported steps
    std::map<int, std::shared_ptr<const ViewPickData>> picks; // steps picked in (cmd_view_pick.cpp)
    std::vector<Global> params; // the number params; their values are read from `values`
    std::vector<double> values;
    std::uint64_t seed = 0;
    std::size_t instances = 0; // instance declarations (the page checks InstancedMesh against it)
    std::uint64_t version = 0; // the version that made it; a failed rebuild after it keeps it
    // An edit at the grammar's last step derives one step more so that it shows: the -n that
    // did, none when the grammar's own length was enough.
    std::optional<int> extended;
    ViewControls controls; // the page's controls it was made with (its "Save as -D" line)
};

} // namespace plant::cli
