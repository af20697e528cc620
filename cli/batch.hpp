// plant run with --seeds, --grid or --shard: many variants of one grammar, each a derivation of
// its own, run on a pool of threads (docs/batch.md). A variant is a seed and one value of every
// --grid parameter; variant n (0-based) takes the seeds in the inner loop and the grids, the first
// --grid outermost, around them.
#pragma once

#include "commands.hpp"
#include "outputs.hpp"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace plant::cli {

// The batch options as written on the command line.
struct BatchOptions {
    std::string seeds;             // A..B (or one seed S)
    std::vector<std::string> grid; // NAME=FROM:TO:STEP or NAME=V1,V2,...
    std::string shard;             // K/N
    std::string manifest;          // .jsonl or .csv
    int jobs = 0;                  // 0: one per core
    bool any() const { return !seeds.empty() || !grid.empty() || !shard.empty() || !manifest.empty(); }
};

// One swept parameter: its values as the text -D receives and placeholders print.
struct GridAxis {
    std::string name;
    std::vector<std::string> values;
};

// The variants of a batch and the slice this process runs.
struct BatchPlan {
    std::optional<std::uint64_t> seed_first; // none: every variant takes --seed or the grammar's
    std::uint64_t seed_count = 1;
    std::vector<GridAxis> axes;
    std::uint64_t shard = 1, shards = 1; // --shard K/N: 1-based K

    std::uint64_t tuples() const;                 // the product of the axes' sizes
    std::uint64_t total() const;                  // tuples() * seed_count: every shard's variants
    std::uint64_t shard_size() const;             // the variants of this shard
    std::uint64_t variant(std::uint64_t i) const; // the i-th variant of this shard: n = K - 1 + i N
    std::uint64_t tuple_of(std::uint64_t n) const { return n / seed_count; }
    std::optional<std::uint64_t> seed_of(std::uint64_t n) const;
    // The value index on every axis of a tuple.
    std::vector<std::size_t> value_indices(std::uint64_t tuple) const;
};

// The most variants one command may describe (the product of the seeds and the grids).
inline constexpr std::uint64_t kMaxVariants = 1'000'000'000;

// Reads --seeds, --grid and --shard. `defines` are the -D overrides (a swept parameter may not
// have one too). Returns the error text of a usage error instead when they do not read.
std::optional<BatchPlan> make_plan(const BatchOptions& o, const std::vector<std::string>& defines,
                                   std::string& error);

// Checks the output paths' placeholders ({seed}, {n}, {NAME} of a --grid parameter) and that
// every variant's paths differ from every other's. Returns the error text, or "" when they do.
std::string check_templates(const BatchPlan& plan, const std::vector<std::string>& outputs);

// A path with its placeholders replaced by variant n's values; `seed` is the seed it ran with.
std::string expand_template(const std::string& path, const BatchPlan& plan, std::uint64_t n,
                            std::uint64_t seed);

// Everything plant run has read and checked, for run_batch.
struct BatchJob {
    GrammarOptions grammar;
    std::vector<std::string> outputs; // templates
    OutputOptions output;
    BatchOptions batch;
    BatchPlan plan;
};

// Runs the shard's variants and writes the manifest. Returns the exit code: 0 when every
// variant was written, 1 when some failed (their manifest rows say why), or a usage, grammar or
// input error found before any variant ran. Ends the process by the signal on SIGINT or SIGTERM,
// having removed every file not completely written.
int run_batch(BatchJob& job);

} // namespace plant::cli
