// The memory budget (memory_budget.hpp).
#include "plant/memory_budget.hpp"

#include "plant/diagnostics.hpp"

#include <fmt/format.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <limits>
#include <unistd.h>
#include <utility>

namespace plant::memory {

namespace {

std::atomic<std::uint64_t> g_limit{0};
std::atomic<std::uint64_t> g_charged{0};
// What this thread is doing, owned by the innermost Stage (or InStage) alive on it; null: the
// derivation. Per thread, so that commands running side by side (the view server's requests,
// --jobs variants) each name their own stage.
thread_local const std::string* t_stage = nullptr;

std::string megabytes(double bytes) {
    return fmt::format("{:.0f} MB", bytes / double(1 << 20));
}

[[noreturn]] void refuse(const std::string& detail) {
    throw RuntimeError(
        RuntimeErrorKind::Memory, Span{},
        fmt::format("{} needs more memory than --max-memory {} allows ({}): raise --max-memory", stage(),
                    megabytes(double(limit())), detail));
}

} // namespace

void set_limit(std::uint64_t bytes) noexcept {
    g_limit.store(bytes, std::memory_order_relaxed);
}

std::uint64_t limit() noexcept {
    return g_limit.load(std::memory_order_relaxed);
}

std::uint64_t charged() noexcept {
    return g_charged.load(std::memory_order_relaxed);
}

void charge(std::size_t bytes) {
    const std::uint64_t before = g_charged.fetch_add(bytes, std::memory_order_relaxed);
    const std::uint64_t cap = limit();
    if (cap == 0 || before + bytes <= cap) return;
    g_charged.fetch_sub(bytes, std::memory_order_relaxed);
    refuse(fmt::format("{} held, {} more asked for", megabytes(double(before)), megabytes(double(bytes))));
}

void release(std::size_t bytes) noexcept {
    g_charged.fetch_sub(bytes, std::memory_order_relaxed);
}

Stage::Stage(std::string what) : what_(std::move(what)), previous_(t_stage) {
    t_stage = &what_;
}

Stage::~Stage() {
    t_stage = previous_;
}

const std::string* Stage::current() noexcept {
    return t_stage;
}

InStage::InStage(const std::string* stage) noexcept : previous_(t_stage) {
    t_stage = stage;
}

InStage::~InStage() {
    t_stage = previous_;
}

std::string stage() {
    return t_stage ? *t_stage : std::string("the derivation");
}

void Reservation::resize(std::size_t bytes) {
    if (bytes > bytes_)
        charge(bytes - bytes_);
    else
        release(bytes_ - bytes);
    bytes_ = bytes;
}

void check_resident() {
    const std::uint64_t cap = limit();
    if (cap == 0) return;
    std::FILE* f = std::fopen("/proc/self/statm", "r");
    if (!f) return;
    unsigned long long size = 0, resident = 0;
    const bool read = std::fscanf(f, "%llu %llu", &size, &resident) == 2;
    std::fclose(f);
    if (!read) return;
    const double bytes = double(resident) * double(::sysconf(_SC_PAGESIZE));
    if (bytes > double(cap + kResidentSlack)) refuse(fmt::format("the process holds {}", megabytes(bytes)));
}

void check_resident_between_steps() {
    // Reading the file costs three system calls (about 15 us): a derivation of many short steps
    // (ABOP 1.31a, 30 steps in 0.2 ms) would spend most of its time here. Between two reads less
    // than 2 ms apart the process cannot have grown past kResidentSlack unseen by the charges.
    // The first call only starts the clock: the stages before the derivation were checked by
    // their own charges, and a derivation shorter than 2 ms cannot grow past the slack either
    // (the first step read the file every run: a fifth of 1.31a's 30 steps, issue 22).
    static std::atomic<std::int64_t> last_ns{std::numeric_limits<std::int64_t>::min()};
    const std::int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(
                                 std::chrono::steady_clock::now().time_since_epoch())
                                 .count();
    const std::int64_t last = last_ns.load(std::memory_order_relaxed);
    if (last == std::numeric_limits<std::int64_t>::min()) {
        last_ns.store(now, std::memory_order_relaxed);
        return;
    }
    if (now - last < 2'000'000) return;
    last_ns.store(now, std::memory_order_relaxed);
    check_resident();
}

} // namespace plant::memory
