// Output files of one command, written under temporary names beside their targets and renamed
// into place only when every one of them has been written: a run that fails, or is stopped by
// SIGINT or SIGTERM, leaves the earlier files as they were and no temporary file behind, nor a
// folder it made for them that stayed empty.
#pragma once

#include "plant/export.hpp"

#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace plant::cli {

class PendingFiles {
  public:
    // Picks a temporary name beside each target and installs SIGINT and SIGTERM handlers that
    // remove the temporary files and the folders made for them that are still empty. When the handler found
    // in place was a function (the REPL's Ctrl-C flag), it is called instead and the files stay: the process
    // goes on and this object removes or renames them. Otherwise the handler removes them and ends the
    // process by the signal, as it would have ended without us.
    explicit PendingFiles(const std::vector<std::string>& targets);
    ~PendingFiles(); // removes what was not committed (and the folders made for it), puts the
                     // old handlers back
    PendingFiles(const PendingFiles&) = delete;
    PendingFiles& operator=(const PendingFiles&) = delete;

    // Writes the k-th file's bytes to its temporary name. Throws ExportError naming the target.
    void write(std::size_t k, const std::string& bytes);
    // The same, the bytes handed by `produce` to the sink it is given, written as they come (a
    // little buffering joins small pieces). When `produce` throws, the file is closed and the
    // exception goes on; the temporary file is removed as an uncommitted one.
    void write_with(std::size_t k, const std::function<void(const ByteSink&)>& produce);
    // Renames every temporary file onto its target. Throws ExportError naming the target when a
    // rename fails (after checking beforehand what can be checked: a target that is a folder).
    void commit();

    // Batch runs (docs/batch.md) keep many PendingFiles at once on several threads: the batch
    // installs SIGINT and SIGTERM handlers of its own that only set `*stop`, and calls this
    // before making any. Objects made while it is set leave the signal handlers alone (their
    // destructor removes what is not committed), and commit() renames nothing once *stop is
    // true: it throws ExportError("interrupted"). nullptr ends that mode.
    static void share_signals(const std::atomic<bool>* stop);

  private:
    std::vector<std::string> targets_, temps_;
    std::unique_ptr<std::atomic<bool>[]> live_; // the temporary file may exist: remove it
    // folders made for the targets, outermost first; reserved up front, so that the signal handler
    // can read the first `made_count_` while a later one is added
    std::vector<std::string> made_dirs_;
    std::atomic<std::size_t> made_count_{0};
    bool owns_signals_ = false; // this object installed the handlers
    bool committed_ = false;    // every file renamed into place
};

// Before any work: why a file could not be written at `target`, or "" when nothing is seen to stop
// it. The folders a run makes for it do not exist yet, so it is the nearest folder that does that
// must be one, and one a file can be made in (tried with an unnamed file, which leaves nothing).
// A name that is a folder is refused too. The message is the one writing the file would give.
std::string output_problem(const std::string& target);

} // namespace plant::cli
