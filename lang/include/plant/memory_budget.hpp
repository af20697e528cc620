// One memory budget for a whole command (plant derive, check, run, repl, view: --max-memory,
// docs/language.md "Limits"). Every large allocation is charged against it before it is made:
// the module string's arrays (BigAllocator), the derivation's per-step tables, the skeleton's
// points, the mesh, the physics particles and the export buffers. A charge that would pass the
// budget throws a RuntimeError of kind Memory naming the stage that asked and the option, and
// charges nothing. A charge is one atomic add: the budget is meant for allocations of whole
// arrays, never for one module.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace plant::memory {

// The budget in bytes; 0 (the default): no budget, nothing is refused. Set by the command line
// before a command starts (a program embedding plant may leave it unset).
void set_limit(std::uint64_t bytes) noexcept;
std::uint64_t limit() noexcept;
// What the live charges add up to.
std::uint64_t charged() noexcept;

// Charges `bytes`, or throws RuntimeError (kind Memory) when that would pass the budget.
void charge(std::size_t bytes);
void release(std::size_t bytes) noexcept;

// What is running, as the message names it ("the derivation", "meshing", "physics", "writing
// 'tree.glb'"): set for as long as the Stage lives, then the one before it is back. Per thread:
// a charge names the stage of the thread that makes it, so commands running side by side (the
// view server's requests, --jobs variants) never name each other's. A thread with none set names
// "the derivation"; a worker thread takes its starter's with InStage.
class Stage {
  public:
    explicit Stage(std::string what);
    ~Stage();
    Stage(const Stage&) = delete;
    Stage& operator=(const Stage&) = delete;
    // This thread's innermost stage (null: none), for InStage on a worker it starts.
    static const std::string* current() noexcept;

  private:
    std::string what_;
    const std::string* previous_;
};
// On a worker thread: names `stage` (Stage::current() of the thread that started it, which
// outlives the worker) for as long as it lives.
class InStage {
  public:
    explicit InStage(const std::string* stage) noexcept;
    ~InStage();
    InStage(const InStage&) = delete;
    InStage& operator=(const InStage&) = delete;

  private:
    const std::string* previous_;
};
std::string stage();

// Bytes charged for as long as it lives, for memory allocated by code that does not charge as
// it goes (std::vector members): sized before that memory is allocated, from what it will hold.
class Reservation {
  public:
    Reservation() = default;
    explicit Reservation(std::size_t bytes) { resize(bytes); }
    ~Reservation() { release(bytes_); }
    // A copy (of an environment, with a copied derivation) holds its own arrays: charged again.
    Reservation(const Reservation& other) { resize(other.bytes_); }
    Reservation& operator=(const Reservation& other) {
        resize(other.bytes_);
        return *this;
    }
    // Charges or gives back the difference; throws (keeping the old size) past the budget.
    void resize(std::size_t bytes);
    std::size_t bytes() const { return bytes_; }

  private:
    std::size_t bytes_ = 0;
};

// The backstop for what no charge sees (small allocations, libraries' own): throws like
// charge() when the process's resident memory (/proc/self/statm) is past the budget plus
// kResidentSlack, the program's own baseline. Reads one small file: call it between stages, not
// in loops. Between derivation steps, check_resident_between_steps reads it at most every 2 ms
// (a call sooner returns at once), so that many short steps do not pay for it; its first call
// in a process only starts that clock.
constexpr std::uint64_t kResidentSlack = std::uint64_t{96} << 20;
void check_resident();
void check_resident_between_steps();

} // namespace plant::memory
