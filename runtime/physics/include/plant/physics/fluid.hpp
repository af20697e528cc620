// SPH air for wind on climbing plants (Hädrich et al. 2017, section 5.3, Eq. 11-13), with the
// kernels and forces of Müller, Charypar and Gross 2003 ("Particle-based fluid simulation for
// interactive applications"). Neighbours come from a uniform grid of cells one support radius
// wide, filled by a counting sort, so every sum runs in the same order on any machine.
//
// Two-way coupling: full-grown plant particles (World) are anisotropic boundary particles. A
// fluid particle near one feels its pressure and drag through the ellipsoid's support (Eq. 13's
// G maps the offset into the unit support), and the plant particle receives the opposite force
// as Eq. 1's external acceleration.
#pragma once

#include "plant/physics/world.hpp"

#include <glm/glm.hpp>

#include <cstdint>
#include <stdexcept>
#include <vector>

namespace plant::physics {

// A wind stream placed in the scene (section 5.3: "an emitter can be used to create a wind stream
// that affects the plant"): air within `radius` of `point` is driven toward `velocity`, fully at
// the centre and less toward the edge. The stream it starts carries on through the air, which is
// what reaches the plant.
struct Emitter {
    glm::dvec3 point{0.0};
    double radius = 0.2;
    glm::dvec3 velocity{0.0};
};

struct FluidSettings {
    double spacing = 0.05;     // initial distance between particles (m)
    double support = 0.1;      // h: kernel support radius (2 spacings)
    double rest_density = 1.3; // rho_0: air, kg/m^3 (the paper: 1.3 - 1.4)
    double stiffness = 20.0;   // k of p = k rho (a gas)
    double viscosity = 0.02;   // mu
    double dt = 0.0025;        // a fluid step; the plant's 25 ms step runs several
    glm::dvec3 domain_lo{-1, 0, -1}, domain_hi{1, 2, 1};
    glm::dvec3 wind{0.0}; // the wind's velocity: particles leaving the domain re-enter upwind
    double drive = 5.0;   // 1/s: how fast a wind brings the air to its velocity
    std::vector<Emitter> emitters;
    double emitter_drive = 40.0; // 1/s: how fast an emitter brings the air at its centre to its velocity
    double coupling = 1.0;       // scales the forces between air and plant
    int threads = 1;
};

// Thrown by Fluid::step when the air has crowded into few grid cells (an emitter or a wind far
// faster than the air can carry, or next to no stiffness): its neighbour search would take time
// quadratic in the particles. Nothing was moved.
struct AirCrowded : std::runtime_error {
    using std::runtime_error::runtime_error;
};

class Fluid {
  public:
    explicit Fluid(FluidSettings s = {}) : s_(s) {}

    // Fills the box [lo, hi] with particles at the centres of cubic cells of the spacing and sets the
    // particle mass so that an interior particle's density is exactly rest_density.
    void fill(const glm::dvec3& lo, const glm::dvec3& hi);
    // Scales every particle's height above the domain's floor by `factor` (tests: compressed air).
    void squeeze(double factor) {
        for (auto& p : x_) p.y = s_.domain_lo.y + (p.y - s_.domain_lo.y) * factor;
    }
    // One step of dt: densities, pressures, pressure and viscosity forces (Eq. 11-12), coupling
    // with `plant` (may be null), the wind and the emitters, symplectic Euler, domain walls and
    // the wind's re-entry.
    void step(World* plant = nullptr);

    std::size_t size() const { return x_.size(); }
    // Positions and velocities in the fluid's own order, which changes from step to step (the
    // particles are kept sorted by grid cell).
    const std::vector<glm::dvec3>& positions() const { return x_; }
    const std::vector<glm::dvec3>& velocities() const { return v_; }
    const std::vector<double>& densities() const { return rho_; }
    double mass() const { return mass_; }
    FluidSettings& settings() { return s_; }

    // Computes densities for the current positions (step() does this first).
    void compute_densities(const World* plant = nullptr);

    // Müller et al. 2003 kernels
    static double poly6(double r2, double h);
    static double spiky_gradient(double r, double h); // magnitude of grad W along -r_hat
    static double viscosity_laplacian(double r, double h);
    // Their constant factors: the passes multiply these by the kernels' polynomials.
    static double poly6_coefficient(double h);
    static double gradient_coefficient(double h);

  private:
    void build_grid();
    // f(index, position) for every particle in the cells a ball of `radius` around p touches
    template <class F> void for_neighbours(const glm::dvec3& p, double radius, F&& f) const;
    // f(q, axes) for each non-empty set of walls within the support of p (a bit per axis), q being
    // p mirrored across all of them
    template <class F> void for_mirrors(const glm::dvec3& p, F&& f) const;
    struct Boundary {
        std::uint32_t particle;
        glm::dvec3 x, v;
        glm::dmat3 G; // offset to normalized support (Eq. 13)
        double volume;
        double reach; // the support's longest half-axis
    };
    void gather_boundary(const World& plant);

    FluidSettings s_;
    std::vector<glm::dvec3> x_, v_, a_;
    std::vector<double> rho_, p_, vol_;
    double mass_ = 0;
    double poly6_c_ = 0, grad_c_ = 0; // kernel coefficients for the support
    // grid
    glm::dvec3 lo_{0.0};
    glm::ivec3 n_{0};
    std::vector<std::uint32_t> cell_start_, order_;
    std::vector<glm::dvec3> sorted_x_; // positions in cell order
    std::vector<glm::vec3> xf_;        // the same in single precision, for rejecting far candidates
    static constexpr std::uint32_t kNeighbours = 64; // list slots per particle (33 at rest)
    std::vector<std::uint32_t> nbr_count_, nbr_;     // neighbour lists within the support
    std::vector<Boundary> boundary_;
    std::vector<glm::dvec3> plant_force_;
};

} // namespace plant::physics
