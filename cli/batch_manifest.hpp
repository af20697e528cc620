// The manifest of a batch (docs/batch.md): one row per variant, in the order of the variants'
// numbers, as JSON lines (.jsonl, .ndjson) or CSV (.csv). Rows arrive from the worker threads
// in any order; the writer puts them in order and streams them to a temporary file beside the
// manifest, renamed into place by finish(). Until then (an interrupted run, an error) no manifest
// file is left, only the one that was there before.
#pragma once

#include "batch.hpp"

#include <cstdio>
#include <map>
#include <mutex>
#include <string>
#include <vector>

namespace plant::cli {

struct ManifestRow {
    std::uint64_t n = 0;               // the variant's number
    std::optional<std::uint64_t> seed; // the seed it ran with (none: it failed before knowing it)
    std::vector<std::string> params;   // the value of every --grid parameter, as text
    std::vector<std::string> outputs;  // the files written (none when it failed)
    std::size_t modules = 0, triangles = 0;
    double ms = 0;             // wall time of its derivation, meshing and files
    std::string status = "ok"; // ok, grammar_error, runtime_error, output_error
    std::string message;       // why it failed: file:line:col: error: ...
};

enum class ManifestFormat { JsonLines, Csv };
// The format named by the manifest's extension; none when it is neither.
std::optional<ManifestFormat> manifest_format(const std::string& path);

class ManifestWriter {
  public:
    // `path` empty: rows are counted and dropped. Throws ExportError when the file cannot be made.
    ManifestWriter(const std::string& path, const BatchPlan& plan);
    ~ManifestWriter(); // removes the temporary file unless finish() renamed it
    ManifestWriter(const ManifestWriter&) = delete;
    ManifestWriter& operator=(const ManifestWriter&) = delete;

    // Row `i` of this shard (variant plan.variant(i)); thread-safe.
    void add(std::uint64_t i, ManifestRow row);
    // Writes the rows still waiting for an earlier one (an interrupted run skips some) and
    // renames the file into place. Throws ExportError.
    void finish();

  private:
    void write_row(const ManifestRow& row);
    void write(const std::string& text);

    std::string path_, temp_;
    ManifestFormat format_ = ManifestFormat::JsonLines;
    std::vector<std::string> param_names_;
    std::FILE* file_ = nullptr;
    std::mutex mutex_;
    std::uint64_t next_ = 0;                       // the next row to write
    std::map<std::uint64_t, ManifestRow> waiting_; // rows after a gap
    bool failed_ = false;                          // a write failed: finish() reports it
};

// The row as one line (no newline), for the tests of the format.
std::string json_row(const ManifestRow& row, const std::vector<std::string>& param_names);
std::string csv_row(const ManifestRow& row);
std::string csv_header(const std::vector<std::string>& param_names);

} // namespace plant::cli
