// plant view: the plant in a browser, derived again on every save (docs/view.md). The pieces:
// the model (compiles, derives and exports, keeping the last good plant), the watcher (inotify on
// every file the grammar read) and the HTTP server (a fixed route table, loopback only).
#pragma once

#include "commands.hpp"
#include "outputs.hpp"
#include "view_http.hpp"

#include <nlohmann/json.hpp>

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace plant::cli {

// One file of the page, built into the program (viewer/embed.cmake writes the table, which ends
// with a null route).
struct ViewAsset {
    const char* route;
    const char* mime;
    const char* begin;
    const char* end;
};
extern const ViewAsset kViewAssets[];
extern const char* const kViewThreeVersion; // empty: three.js was not installed when plant was built

// What the page may change: param values (numbers only) and the seed. Everything else is fixed by
// the command line.
struct ViewControls {
    std::map<std::string, double> params;
    std::optional<std::uint64_t> seed;
};

// A click on the page (docs/view.md, picking), in the plant's own coordinates: the point hit,
// and for an organ or instance the origin of the placement hit.
struct ViewPick {
    enum Kind { Tube, Organ } kind = Tube;
    glm::dvec3 point{0.0}, origin{0.0};
};
struct ViewPickData; // a step's interpreted string and skeleton (cmd_view_pick.cpp)
// The answer to a pick at `step` of derivation `d`, as JSON; `data` is made on first use and
// kept by the caller for the next pick at that step.
std::string view_pick_json(const Program& program, const Derivation& d, int step,
                           std::shared_ptr<const ViewPickData>& data, const ViewPick& q);

// An edit made on the page to an environment (docs/view.md, editing climbers): one call of an
// edit method (`ivy.cut(14)`, `ivy.pull(14, vec3(0, 1, 0.2))`), run before step `step + 1` as
// the REPL's edits are. Arguments: a number each, three for a vec3.
struct ViewEdit {
    int step = 0;
    std::string env, method;
    std::vector<std::vector<double>> args;
};

// The `on before_step` hook that runs the edits (empty without any), and the environments'
// edit methods the page can call, as JSON rows (cmd_view_edit.cpp).
std::string view_edit_hook(const std::vector<std::pair<int, std::string>>& edits);
nlohmann::json view_edit_methods(const Program& program);

// The grammar, derived with the command line's options and the page's controls; the last good
// derivation stays when the grammar stops compiling. Thread-safe.
class ViewModel {
  public:
    ViewModel(GrammarOptions options, OutputOptions output, std::string scratch_dir);
    ~ViewModel();
    // Compiles and derives again (a save, a control). Returns the new version's number.
    std::uint64_t rebuild();
    // Sets the controls (checked against the params the grammar declares) and rebuilds. Returns
    // an error message, empty on success.
    std::string set_controls(const ViewControls& controls);
    // Checks an edit against the grammar's environments (an edit method of a declared one, its
    // arguments' count and types, finite numbers), keeps it and rebuilds. Returns an error
    // message, empty on success. undo_edit drops the last edit (false when there is none).
    std::string add_edit(const ViewEdit& edit);
    bool undo_edit();
    // The state as JSON: version, counts per kept step, params, seed, the error if any.
    std::string state_json() const;
    // The GLB of kept step k (the last step when k < 0); none when there is no plant or k is not kept.
    std::optional<std::string> glb(int step);
    // What was hit at kept step k (the last when k < 0), as JSON: the segment or organ, the
    // module that drew it (name, identity, parameters) and its graph node if a parameter names
    // one; none when there is no plant or k is not kept.
    std::optional<std::string> pick(int step, const ViewPick& q);
    // Every file the grammar read, for the watcher (absolute paths).
    std::set<std::string> watched_files() const;
    std::uint64_t version() const;

    struct Built; // a compiled program and its kept steps (cmd_view_model.cpp)

  private:
    const Derivation* kept_step(int& step) const; // (with mutex_ held)
    GrammarOptions options_;
    OutputOptions output_;
    std::string scratch_;
    mutable std::mutex mutex_;    // guards everything below
    std::mutex build_mutex_;      // one rebuild at a time
    std::unique_ptr<Built> good_; // the last good plant
    ViewControls controls_;
    std::vector<std::pair<int, std::string>> edits_; // (step, statement), in the order made
    std::string error_; // the last rebuild's diagnostics; empty when it succeeded
    double derive_ms_ = 0;
    std::uint64_t version_ = 0;
    std::set<std::string> watched_;
};

// Wakes whoever waits for a new version (the page's event streams).
class ViewEvents {
  public:
    void publish(std::uint64_t version);
    // Waits up to `ms` for a version after `seen`; returns the newest, or `seen` on timeout/stop.
    std::uint64_t wait(std::uint64_t seen, int ms);
    void stop();
    bool stopped() const { return stopped_; }

  private:
    std::mutex mutex_;
    std::condition_variable cv_;
    std::uint64_t version_ = 0;
    std::atomic<bool> stopped_{false};
};

// Watches the files (inotify on their folders, as editors replace files by renaming) and calls
// `changed` after a burst of events settles. Runs until `stop` is set; started on its own thread.
void watch_files(ViewModel& model, ViewEvents& events, const std::atomic<bool>& stop);

// Serves the page, the model and the events on 127.0.0.1:port through the HTTP server module's
// `serve` (view_http.hpp) until stopped (serve_view returns then: the port, or -1 when it could
// not bind). `port` 0 picks a free port; `on_listening` gets the bound port before serving.
struct ViewServerOptions {
    int port = 0;
    std::function<void(int port)> on_listening;
};
int serve_view(view_http::ServeFunction serve, ViewModel& model, ViewEvents& events,
               const ViewServerOptions& options, std::function<void(std::function<void()>)> set_stopper);

} // namespace plant::cli
