// plant view's model: compile, derive keeping every step's state, export GLB on demand.
#include "cmd_view.hpp"
#include "cmd_view_built.hpp"

#include "plant/environment_phase.hpp"
#include "plant/graph.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace plant::cli {

namespace fs = std::filesystem;

namespace {

// Intermediate steps are kept (for the step slider) while their strings hold at most this many
// modules in all; past it only the last step is kept.
constexpr std::size_t kKeptModules = 20'000'000;

std::string absolute(const std::string& path) {
    std::error_code ec;
    fs::path p = fs::weakly_canonical(fs::absolute(path, ec), ec);
    return p.string();
}

std::string number_text(double v) {
    return fmt::format("{}", v);
}

} // namespace

ViewModel::ViewModel(GrammarOptions options, OutputOptions output, std::string scratch_dir)
    : options_(std::move(options)), output_(output), scratch_(std::move(scratch_dir)) {
    watched_.insert(absolute(options_.file));
}

ViewModel::~ViewModel() = default;

std::uint64_t ViewModel::version() const {
    std::lock_guard lock(mutex_);
    return version_;
}

std::set<std::string> ViewModel::watched_files() const {
    std::lock_guard lock(mutex_);
    return watched_;
}

static void collect_files(const SourceManager& sources, const Program* program, std::set<std::string>& out) {
    for (std::size_t k = 0; k < sources.size(); ++k) {
        const std::string& name = sources.file(static_cast<std::uint32_t>(k)).name();
        if (!name.empty() && name[0] != '<') out.insert(absolute(name));
    }
    if (!program) return;
    for (const auto& s : program->surfaces)
        if (s.kind == SurfaceKind::Load) out.insert(absolute(s.path));
    for (const auto& t : program->textures) out.insert(absolute(t.path));
    for (const auto& e : program->environments)
        for (const auto& a : e.args)
            if (a.type == ValueType::String && !a.text.empty()) out.insert(absolute(a.text));
}

// Derives `program`, keeping a copy of the derivation after every step while they fit.
static void derive_steps(ViewModel::Built& b, const DeriveOptions& options, const std::set<int>& edit_steps) {
    auto d = std::make_unique<Derivation>(*b.program, options);
    d->start();
    if (edit_steps.count(d->target_steps())) { // an edit at the last step: one step more shows it
        DeriveOptions longer = options;
        longer.steps = d->target_steps() + 1;
        d = std::make_unique<Derivation>(*b.program, longer);
        d->start();
        b.extended = *longer.steps;
    }
    std::size_t kept = d->string().size();
    auto keep = [&](std::unique_ptr<Derivation> copy) {
        b.modules.push_back(copy ? copy->string().size() : 0);
        b.steps.push_back(std::move(copy));
    };
    keep(std::make_unique<Derivation>(*d));
    for (;;) {
        // step() says false after the last step too: a step was made when the count moved
        const int before = d->steps_done();
        const bool more = d->step();
        if (d->steps_done() == before) break;
        kept += d->string().size();
        // a decomposition graph is copied with each step: its nodes count too (a node and its
        // values weigh about what a hundred modules do)
        if (const DecompositionGraph* graph = d->run_state().graph()) kept += graph->size() * 100;
        keep(kept <= kKeptModules ? std::make_unique<Derivation>(*d) : nullptr);
        b.modules.back() = d->string().size();
        if (!more) break;
    }
    d->finish();
    b.modules.back() = d->string().size();
    b.steps.back() = std::move(d);
}

std::uint64_t ViewModel::rebuild() {
    std::lock_guard build(build_mutex_);
    GrammarOptions g = options_;
    std::set<int> edit_steps; // an edit runs before the step after its own
    ViewControls controls;
    {
        std::lock_guard lock(mutex_);
        controls = controls_;
        for (const auto& [name, value] : controls_.params)
            g.defines.push_back(name + "=" + number_text(value));
        if (controls_.seed) g.seed = controls_.seed;
        g.appended = view_edit_hook(edits_);
        for (const auto& e : edits_) edit_steps.insert(e.first);
    }
    g.color = false;
    const auto t0 = std::chrono::steady_clock::now();
    auto b = std::make_unique<Built>();
    b->controls = std::move(controls);
    b->sources = std::make_unique<SourceManager>();
    std::string messages;
    int exit_code = kOk;
    b->program = load_program(g, *b->sources, exit_code, &messages);
    std::set<std::string> files;
    collect_files(*b->sources, b->program.get(), files);
    if (b->program) {
        DeriveOptions opt = derive_options(g);
        b->phase = std::make_unique<TurtleEnvironmentPhase>();
        opt.environment_phase = b->phase.get();
        opt.on_print = [](const std::string&) {};
        try {
            derive_steps(*b, opt, edit_steps);
        } catch (const RuntimeError& e) {
            messages += render(Diagnostic{Severity::Error, e.span, e.message, {}}, *b->sources, false);
            b->program.reset();
        } catch (const std::bad_alloc&) {
            messages += "plant: out of memory (lower --max-modules or the derivation length)\n";
            b->program.reset();
        }
    }
    if (b->program) {
        for (const Global& gl : b->program->globals)
            if (gl.kind == GlobalKind::Param && gl.type == ValueType::Number) {
                b->params.push_back(gl);
                b->values.push_back(b->program->global_values[gl.slot]);
            }
        b->seed = b->steps.back()->seed();
        b->instances = b->program->instances ? b->program->instances->size() : 0;
    }
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    std::lock_guard lock(mutex_);
    watched_.insert(files.begin(), files.end());
    error_ = b->program ? std::string() : (messages.empty() ? "plant: the grammar failed" : messages);
    if (b->program) {
        b->version = version_ + 1;
        good_ = std::move(b);
        derive_ms_ = ms;
    }
    return ++version_;
}

std::string ViewModel::set_controls(const ViewControls& controls) {
    {
        std::lock_guard lock(mutex_);
        for (const auto& [name, value] : controls.params) {
            bool known = false;
            if (good_)
                for (const auto& p : good_->params) known = known || p.name == name;
            if (!known) return fmt::format("'{}' is not a param of the grammar", name);
            if (!std::isfinite(value)) return fmt::format("the value of '{}' is not a finite number", name);
        }
        controls_ = controls;
    }
    rebuild();
    return {};
}

std::string ViewModel::state_json() const {
    std::lock_guard lock(mutex_);
    nlohmann::json j;
    j["version"] = version_;
    j["file"] = options_.file;
    j["error"] = error_.empty() ? nlohmann::json() : nlohmann::json(error_);
    j["three"] = kViewThreeVersion;
    if (good_) {
        j["plant"] = good_->version;
        j["modules"] = good_->modules;
        nlohmann::json kept = nlohmann::json::array();
        for (const auto& s : good_->steps) kept.push_back(s != nullptr);
        j["kept"] = kept;
        j["seed"] = std::to_string(good_->seed);
        nlohmann::json params = nlohmann::json::array();
        for (std::size_t k = 0; k < good_->params.size(); ++k) {
            const Global& p = good_->params[k];
            nlohmann::json one = {{"name", p.name}, {"value", good_->values[k]}};
            if (p.has_range) { // `param r = 0.9 in 0.5 .. 1.0;`: the page draws a slider
                one["low"] = p.low;
                one["high"] = p.high;
                one["whole"] = p.whole; // a count: the slider moves by whole steps
            }
            params.push_back(std::move(one));
        }
        j["params"] = params;
        j["instances"] = good_->instances;
        j["edit_methods"] = view_edit_methods(*good_->program);
        j["derive_ms"] = derive_ms_;
    }
    // the command line that grows what is shown: the controls of the plant shown, never values
    // whose derivation failed (a param outside its range); a -D the controls override is left out
    const ViewControls& shown = good_ ? good_->controls : controls_;
    std::string cmd = "plant run " + options_.file;
    for (const auto& d : options_.defines)
        if (!shown.params.count(d.substr(0, d.find('=')))) cmd += " -D " + d;
    for (const auto& [name, value] : shown.params) cmd += " -D " + name + "=" + number_text(value);
    if (shown.seed)
        cmd += fmt::format(" --seed {}", *shown.seed);
    else if (options_.seed)
        cmd += fmt::format(" --seed {}", *options_.seed);
    if (good_ && good_->extended)
        cmd += fmt::format(" -n {}", *good_->extended);
    else if (options_.steps)
        cmd += fmt::format(" -n {}", *options_.steps);
    j["command"] = cmd;
    nlohmann::json edits = nlohmann::json::array();
    for (const auto& [step, statement] : edits_) edits.push_back({{"step", step}, {"call", statement}});
    j["edits"] = edits;
    // what to add to the grammar for `plant run` to make the edited plant too
    j["edit_hook"] = view_edit_hook(edits_);
    return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

// Kept step `step` of the last good plant (the last step when `step` is out of range, which
// `step` is then set to); null without a plant or when that step was not kept.
const Derivation* ViewModel::kept_step(int& step) const {
    if (!good_) return nullptr;
    const int last = static_cast<int>(good_->steps.size()) - 1;
    if (step < 0 || step > last) step = last;
    return good_->steps[static_cast<std::size_t>(step)].get();
}

std::optional<std::string> ViewModel::glb(int step) {
    std::lock_guard lock(mutex_);
    const Derivation* d = kept_step(step);
    if (!d) return std::nullopt;
    if (auto it = good_->glb.find(step); it != good_->glb.end()) return it->second;
    // the export `plant run -o x.glb` does, into the scratch folder, read back
    const std::string path = scratch_ + "/model.glb";
    write_outputs(*good_->program, *d, {path}, output_);
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    fs::remove(path);
    if (good_->glb.size() > 64) good_->glb.clear(); // bounded: a few dozen steps exported at most
    return good_->glb[step] = bytes.str();
}

std::optional<std::string> ViewModel::pick(int step, const ViewPick& q) {
    std::lock_guard lock(mutex_);
    const Derivation* d = kept_step(step);
    if (!d) return std::nullopt;
    if (good_->picks.size() > 8 && !good_->picks.count(step)) good_->picks.clear(); // a few steps' skeletons
    return view_pick_json(*good_->program, *d, step, good_->picks[step], q);
}

void ViewEvents::publish(std::uint64_t version) {
    {
        std::lock_guard lock(mutex_);
        version_ = std::max(version_, version);
    }
    cv_.notify_all();
}

std::uint64_t ViewEvents::wait(std::uint64_t seen, int ms) {
    std::unique_lock lock(mutex_);
    cv_.wait_for(lock, std::chrono::milliseconds(ms), [&] { return stopped_ || version_ > seen; });
    return stopped_ ? seen : std::max(seen, version_);
}

void ViewEvents::stop() {
    {
        std::lock_guard lock(mutex_);
        stopped_ = true;
    }
    cv_.notify_all();
}

} // namespace plant::cli
