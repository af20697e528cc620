// The memory budget's stage names (plant/memory_budget.hpp): per thread, so that commands running
// side by side name their own stage.
#include "plant/diagnostics.hpp"
#include "plant/memory_budget.hpp"

#include <catch2/catch.hpp>

#include <string>
#include <thread>

using namespace plant;

namespace {

// The message of the charge past the budget made on this thread.
std::string refused(std::size_t bytes) {
    try {
        memory::charge(bytes);
        memory::release(bytes);
    } catch (const RuntimeError& e) {
        return e.message;
    }
    return "";
}

struct Budget {
    std::uint64_t saved = memory::limit();
    explicit Budget(std::uint64_t bytes) { memory::set_limit(bytes); }
    ~Budget() { memory::set_limit(saved); }
};

} // namespace

TEST_CASE("each thread's charge names its own stage", "[memory]") {
    Budget budget(memory::charged() + (std::uint64_t{1} << 20));
    const std::size_t too_much = std::size_t{1} << 30;
    memory::Stage meshing("meshing");
    CHECK(refused(too_much).find("meshing needs more memory than --max-memory") == 0);
    std::string other, inherited;
    std::thread([&] {
        other = refused(too_much); // a thread that set none: not this thread's "meshing"
        memory::Stage writing("writing 'a.glb'");
        inherited = refused(too_much);
    }).join();
    CHECK(other.find("the derivation needs more memory") == 0);
    CHECK(inherited.find("writing 'a.glb' needs more memory") == 0);
    // a worker thread takes its starter's stage when told to, and the starter keeps its own
    const std::string* mine = memory::Stage::current();
    std::thread([&] {
        memory::InStage named(mine);
        inherited = refused(too_much);
    }).join();
    CHECK(inherited.find("meshing needs more memory") == 0);
    {
        memory::Stage inner("physics");
        CHECK(refused(too_much).find("physics needs") == 0);
    }
    CHECK(refused(too_much).find("meshing needs") == 0);
}
