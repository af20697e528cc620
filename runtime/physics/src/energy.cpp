// The energy budget (docs/physics.md, "The energy budget"). The solver's length and bending sweep
// moves a child after its parent and never the parent after its child (follow-the-leader, as the
// paper's "particles always follow their parents"); such a correction is not the gradient of a
// potential, so it can do work, and in a growing free shoot it does: the shoot swings faster each
// derivation step until it circles at metres a second. So each step keeps an account of every
// particle's mechanical energy (kinetic plus gravitational), after the way Dinev et al. 2018
// ("Stabilizing integrators for real-time physics") track a system's energy with the events that
// change it: from the step's start to its end a particle may gain only what its forcing (the wind
// and the air, Eq. 1's a_e) did on it, less the step's damping. One that would end the step with
// more has its velocity scaled down to that. Positions are not touched, so the shape the solver
// found stays; only the motion the solver invented goes. The account is per particle, not per
// plant: with one account per plant, energy a heavy stem gave up as it settled paid for its light
// tips to whip (measured in docs/physics.md).
#include "plant/physics/world.hpp"

#include <cmath>

namespace plant::physics {

void World::open_energy_budget() {
    const std::size_t n = x_.size();
    auto& forcing = scratch_.forcing;
    auto& before = scratch_.energy_before;
    forcing.assign(n, glm::dvec3(0.0));
    before.assign(n, 0.0);
    if (external_.size() < n) external_.resize(n, glm::dvec3(0.0));
    const glm::dvec3 g = settings_.gravity;
    for (std::uint32_t i = 0; i < n; ++i) {
        if (!alive_[i] || fixed_[i]) continue;
        forcing[i] = wind_ + external_[i];
        before[i] = 0.5 * glm::dot(v_[i], v_[i]) - glm::dot(g, x_[i]); // per unit mass
    }
}

void World::close_energy_budget() {
    const std::size_t n = x_.size();
    const auto& old = scratch_.old;
    // a particle held by the hand is given work the account cannot see: it is left as it is (the
    // rest of its plant is not: the hand moves it through the solver, as growth and anchors do)
    auto& held = scratch_.held;
    held.assign(n, 0);
    for (const auto& pull : pulls_)
        if (pull.first < n) held[pull.first] = 1;
    const glm::dvec3 g = settings_.gravity;
    const double keep = (1.0 - settings_.damping) * (1.0 - settings_.damping);
    for (std::uint32_t i = 0; i < n; ++i) {
        if (!alive_[i] || fixed_[i] || held[i]) continue;
        const double kinetic = 0.5 * glm::dot(v_[i], v_[i]);
        if (kinetic <= 0) continue;
        const double work = glm::dot(scratch_.forcing[i], x_[i] - old[i]);
        // what the particle may have as kinetic energy: its energy at the start and the forcing's
        // work, less the height it has gained, damped as the step damps its velocity
        const double allowed = (scratch_.energy_before[i] + work + glm::dot(g, x_[i])) * keep;
        if (kinetic > allowed) v_[i] *= allowed > 0 ? std::sqrt(allowed / kinetic) : 0.0;
    }
}

} // namespace plant::physics
