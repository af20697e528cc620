// The variants of a batch: --seeds, --grid and --shard as read from the command line, and the
// output paths' placeholders (docs/batch.md).
#include "batch.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <map>
#include <set>

namespace plant::cli {

namespace {

constexpr std::uint64_t kMaxGridValues = 1'000'000;
constexpr std::uint64_t kMaxShards = 1'000'000;

std::string shown(const std::string& text) {
    return "'" + escape_controls(text.size() > 60 ? text.substr(0, 60) + "..." : text) + "'";
}

bool read_whole(std::string_view text, std::uint64_t& v) {
    const char* end = text.data() + text.size();
    auto r = std::from_chars(text.data(), end, v);
    return !text.empty() && r.ec == std::errc() && r.ptr == end;
}

bool read_number(const std::string& text, double& v) {
    char* end = nullptr;
    v = std::strtod(text.c_str(), &end);
    return !text.empty() && end == text.c_str() + text.size() && std::isfinite(v) && text[0] != ' ';
}

bool is_identifier(std::string_view s) {
    if (s.empty() || std::isdigit(static_cast<unsigned char>(s[0]))) return false;
    return std::all_of(s.begin(), s.end(),
                       [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

// A value as -D and the placeholders write it: twelve significant digits (so 0.5 + 2 * 0.1 is
// 0.7, not 0.7000000000000001), then the shortest text that reads back to that.
std::string value_text(double v) {
    const double rounded = std::strtod(fmt::format("{:.12g}", v).c_str(), nullptr) + 0.0;
    return format_double(rounded);
}

bool read_seeds(const std::string& text, BatchPlan& plan, std::string& error) {
    const auto dots = text.find("..");
    std::uint64_t a = 0, b = 0;
    const bool ok = dots == std::string::npos ? read_whole(text, a) && (b = a, true)
                                              : read_whole(std::string_view(text).substr(0, dots), a) &&
                                                    read_whole(std::string_view(text).substr(dots + 2), b);
    if (!ok || b < a) {
        error =
            fmt::format("--seeds expects A..B, whole numbers with A <= B (as 1..100), found {}", shown(text));
        return false;
    }
    plan.seed_first = a;
    plan.seed_count = b - a + 1; // b - a < 2^64 - 1 unless the whole range: capped below
    if (plan.seed_count == 0 || plan.seed_count > kMaxVariants) {
        error = fmt::format("--seeds {} names more than {} seeds", shown(text), kMaxVariants);
        return false;
    }
    return true;
}

// NAME=FROM:TO:STEP or NAME=V1,V2,...
bool read_axis(const std::string& text, GridAxis& axis, std::string& error) {
    const auto eq = text.find('=');
    axis.name = text.substr(0, eq);
    const std::string usage = "--grid expects NAME=FROM:TO:STEP (as r1=0.5:0.9:0.1) or NAME=V1,V2,...";
    if (eq == std::string::npos || !is_identifier(axis.name)) {
        error = fmt::format("{}, found {}", usage, shown(text));
        return false;
    }
    const std::string values = text.substr(eq + 1);
    std::vector<std::string> parts;
    const char sep = values.find(':') != std::string::npos ? ':' : ',';
    for (std::size_t at = 0;;) {
        const auto next = values.find(sep, at);
        parts.push_back(values.substr(at, next - at));
        if (next == std::string::npos) break;
        at = next + 1;
    }
    std::vector<double> v(parts.size());
    for (std::size_t k = 0; k < parts.size(); ++k)
        if (!read_number(parts[k], v[k])) {
            error = fmt::format("{}: {} is not a finite number", usage, shown(parts[k]));
            return false;
        }
    if (sep == ',') {
        for (double x : v) axis.values.push_back(value_text(x));
    } else {
        const double steps = parts.size() == 3 && v[2] != 0 ? (v[1] - v[0]) / v[2] : -1;
        if (!(steps > -1e-9) || steps + 1 > double(kMaxGridValues)) {
            error = fmt::format("{}: {} must go from FROM to TO by STEP (STEP not 0, its sign that of TO - "
                                "FROM) in at most {} values",
                                usage, shown(text), kMaxGridValues);
            return false;
        }
        const auto count = static_cast<std::uint64_t>(std::floor(steps + 1e-9)) + 1;
        for (std::uint64_t k = 0; k < count; ++k) axis.values.push_back(value_text(v[0] + double(k) * v[2]));
    }
    std::set<std::string> seen;
    for (const auto& x : axis.values)
        if (!seen.insert(x).second) {
            error = fmt::format("--grid {} gives the value {} twice (a step below twelve significant "
                                "digits?)",
                                shown(text), x);
            return false;
        }
    return true;
}

bool read_shard(const std::string& text, BatchPlan& plan, std::string& error) {
    const auto slash = text.find('/');
    const bool ok = slash != std::string::npos &&
                    read_whole(std::string_view(text).substr(0, slash), plan.shard) &&
                    read_whole(std::string_view(text).substr(slash + 1), plan.shards);
    if (!ok || plan.shards < 1 || plan.shards > kMaxShards || plan.shard < 1 || plan.shard > plan.shards) {
        error = fmt::format("--shard expects K/N with 1 <= K <= N <= {} (as 3/8: the third of eight "
                            "slices), found {}",
                            kMaxShards, shown(text));
        return false;
    }
    return true;
}

// The placeholders of a path, in order; "" in `error` unless one is unknown.
std::vector<std::string> placeholders(const std::string& path, const BatchPlan& plan, std::string& error) {
    std::vector<std::string> names;
    for (std::size_t at = path.find('{'); at != std::string::npos; at = path.find('{', at + 1)) {
        const auto close = path.find('}', at);
        if (close == std::string::npos) break;
        const std::string name = path.substr(at + 1, close - at - 1);
        const bool axis = std::any_of(plan.axes.begin(), plan.axes.end(),
                                      [&](const GridAxis& a) { return a.name == name; });
        if (name != "seed" && name != "n" && !axis) {
            std::string known = "{seed}, {n}";
            for (const auto& a : plan.axes) known += ", {" + a.name + "}";
            error = fmt::format("unknown placeholder {{{}}} in the output {}: use {}", escape_controls(name),
                                shown(path), known);
            return {};
        }
        names.push_back(name);
    }
    return names;
}

} // namespace

std::uint64_t BatchPlan::tuples() const {
    std::uint64_t t = 1;
    for (const auto& a : axes) t *= a.values.size(); // bounded by make_plan
    return t;
}

std::uint64_t BatchPlan::total() const {
    return tuples() * seed_count;
}

std::uint64_t BatchPlan::shard_size() const {
    const std::uint64_t all = total();
    return all >= shard ? (all - shard) / shards + 1 : 0;
}

std::uint64_t BatchPlan::variant(std::uint64_t i) const {
    return shard - 1 + i * shards;
}

std::optional<std::uint64_t> BatchPlan::seed_of(std::uint64_t n) const {
    if (!seed_first) return std::nullopt;
    return *seed_first + n % seed_count;
}

std::vector<std::size_t> BatchPlan::value_indices(std::uint64_t tuple) const {
    std::vector<std::size_t> at(axes.size());
    for (std::size_t k = axes.size(); k-- > 0;) {
        at[k] = static_cast<std::size_t>(tuple % axes[k].values.size());
        tuple /= axes[k].values.size();
    }
    return at;
}

std::optional<BatchPlan> make_plan(const BatchOptions& o, const std::vector<std::string>& defines,
                                   std::string& error) {
    BatchPlan plan;
    if (!o.seeds.empty() && !read_seeds(o.seeds, plan, error)) return std::nullopt;
    std::uint64_t total = plan.seed_count;
    for (const auto& g : o.grid) {
        GridAxis axis;
        if (!read_axis(g, axis, error)) return std::nullopt;
        for (const auto& a : plan.axes)
            if (a.name == axis.name) {
                error = fmt::format("--grid sweeps {} twice: give each parameter one --grid", axis.name);
                return std::nullopt;
            }
        for (const auto& d : defines)
            if (d.substr(0, d.find('=')) == axis.name) {
                error = fmt::format("{} is set by -D and swept by --grid: keep one of them", axis.name);
                return std::nullopt;
            }
        if (total > kMaxVariants / axis.values.size()) {
            error = fmt::format("--seeds and --grid make more than {} variants", kMaxVariants);
            return std::nullopt;
        }
        total *= axis.values.size();
        plan.axes.push_back(std::move(axis));
    }
    if (!o.shard.empty() && !read_shard(o.shard, plan, error)) return std::nullopt;
    return plan;
}

namespace {

// A path with every placeholder replaced by one mark: two outputs with the same shape differ only
// in which placeholders they hold ('a-{seed}.txt', 'a-{n}.txt'), so one variant's {seed} and
// another's {n} can name the same file, and the later one overwrites the earlier.
std::string shape_of(const std::string& path) {
    std::string out;
    std::size_t from = 0;
    for (std::size_t open = path.find('{'); open != std::string::npos; open = path.find('{', open + 1)) {
        const auto close = path.find('}', open);
        if (close == std::string::npos) break;
        out += path.substr(from, open - from) + '\x01';
        from = close + 1;
        open = close;
    }
    return out + path.substr(from);
}

} // namespace

// (an output named twice was refused before, by plant run's outputs_distinct)
std::string check_templates(const BatchPlan& plan, const std::vector<std::string>& outputs) {
    std::string error;
    std::map<std::string, std::string> shapes; // shape -> the first output with it
    for (const auto& path : outputs) {
        const auto names = placeholders(path, plan, error);
        if (!error.empty()) return error;
        if (plan.total() < 2) continue;
        if (const auto [it, first] = shapes.emplace(shape_of(path), path); !first)
            return fmt::format("the outputs {} and {} differ only in their placeholders, so one variant's "
                               "file can be another's and be written over: make the rest of their names "
                               "differ too",
                               shown(it->second), shown(path));
        auto has = [&](const std::string& n) {
            return std::find(names.begin(), names.end(), n) != names.end();
        };
        std::string missing;
        if (plan.seed_count > 1 && !has("seed")) missing += " {seed}";
        for (const auto& a : plan.axes)
            if (a.values.size() > 1 && !has(a.name)) missing += " {" + a.name + "}";
        if (!has("n") && !missing.empty())
            return fmt::format("the output {} would be the same file for several of the {} variants: put "
                               "{{n}} (the variant's number) or{} in it",
                               shown(path), plan.total(), missing);
    }
    return "";
}

std::string expand_template(const std::string& path, const BatchPlan& plan, std::uint64_t n,
                            std::uint64_t seed) {
    const auto at = plan.value_indices(plan.tuple_of(n));
    std::string out;
    std::size_t from = 0;
    for (std::size_t open = path.find('{'); open != std::string::npos; open = path.find('{', open + 1)) {
        const auto close = path.find('}', open);
        if (close == std::string::npos) break;
        const std::string name = path.substr(open + 1, close - open - 1);
        out += path.substr(from, open - from);
        if (name == "seed")
            out += std::to_string(seed);
        else if (name == "n")
            out += std::to_string(n);
        else
            for (std::size_t k = 0; k < plan.axes.size(); ++k)
                if (plan.axes[k].name == name) out += plan.axes[k].values[at[k]];
        from = close + 1;
        open = close;
    }
    return out + path.substr(from);
}

} // namespace plant::cli
