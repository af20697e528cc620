#include "plant/physics/fluid.hpp"

#include "cells.hpp"
#include "parallel.hpp"

#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <thread>

namespace plant::physics {

namespace {

constexpr double kPi = std::numbers::pi;
// The most particles a grid cell may hold on average, seen from a particle (the sum of the
// cells' squared counts over the particle count) before a step gives up: see build_grid.
constexpr int kMaxCrowding = 8;

} // namespace

// Müller et al. 2003: the constants in front of the kernels. Eq. 21's spiky gradient and Eq.
// 22's viscosity Laplacian share 45 / (pi h^6).
double Fluid::poly6_coefficient(double h) {
    return 315.0 / (64.0 * kPi * std::pow(h, 9));
}
double Fluid::gradient_coefficient(double h) {
    return 45.0 / (kPi * std::pow(h, 6));
}

// Müller et al. 2003, Eq. 20: W_poly6 for densities
double Fluid::poly6(double r2, double h) {
    const double h2 = h * h;
    if (r2 >= h2) return 0;
    const double d = h2 - r2;
    return poly6_coefficient(h) * d * d * d;
}

// Müller et al. 2003, Eq. 21: the spiky kernel's gradient, for pressure
double Fluid::spiky_gradient(double r, double h) {
    if (r >= h) return 0;
    const double d = h - r;
    return gradient_coefficient(h) * d * d;
}

// Müller et al. 2003, Eq. 22: the viscosity kernel's Laplacian
double Fluid::viscosity_laplacian(double r, double h) {
    if (r >= h) return 0;
    return gradient_coefficient(h) * (h - r);
}

void Fluid::fill(const glm::dvec3& lo, const glm::dvec3& hi) {
    const double sp = s_.spacing;
    // cell centres, half a spacing in from the box's faces: mirrored across a wall, the lattice
    // goes on without a gap or a double
    glm::ivec3 n = glm::max(glm::ivec3(glm::floor((hi - lo) / sp + 1e-9)), glm::ivec3(1));
    for (int z = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y)
            for (int x = 0; x < n.x; ++x) {
                x_.push_back(lo + (glm::dvec3(x, y, z) + 0.5) * sp);
                v_.push_back(s_.wind);
            }
    // an interior lattice particle's kernel sum fixes the mass: rho_0 = m * sum W
    const double h = s_.support;
    const int reach = static_cast<int>(std::ceil(h / sp));
    double sum = 0;
    for (int z = -reach; z <= reach; ++z)
        for (int y = -reach; y <= reach; ++y)
            for (int x = -reach; x <= reach; ++x) sum += poly6(sp * sp * (x * x + y * y + z * z), h);
    mass_ = s_.rest_density / sum;
    rho_.assign(x_.size(), s_.rest_density);
    p_.assign(x_.size(), 0);
    a_.assign(x_.size(), glm::dvec3(0.0));
}

void Fluid::build_grid() {
    // cells half a support wide: a neighbourhood is 5 x 5 rows of 5 cells, each row one run of
    // the cell-sorted arrays, about 125 candidates for the 33 neighbours at rest
    const double cell = s_.support / 2;
    lo_ = s_.domain_lo - glm::dvec3(s_.support);
    n_ = glm::max(glm::ivec3(glm::floor((s_.domain_hi - s_.domain_lo + 2 * s_.support) / cell)) + 1,
                  glm::ivec3(1));
    const std::size_t cells = static_cast<std::size_t>(n_.x) * n_.y * n_.z;
    cell_start_.assign(cells + 1, 0);
    std::vector<std::uint32_t> cell_of(x_.size());
    for (std::size_t i = 0; i < x_.size(); ++i) {
        glm::ivec3 c = cell_index((x_[i] - lo_) / cell, glm::ivec3(0), n_ - 1);
        cell_of[i] = static_cast<std::uint32_t>((static_cast<std::size_t>(c.z) * n_.y + c.y) * n_.x + c.x);
        ++cell_start_[cell_of[i] + 1];
    }
    // a particle's neighbour search visits the cells around its own, so the work of a pass is
    // about the sum of the cells' squared counts: about one particle a cell at rest, a few where
    // the air is compressed; far more and the search would be quadratic in the particles
    double crowding = 0;
    for (std::size_t c = 1; c <= cells; ++c) crowding += double(cell_start_[c]) * double(cell_start_[c]);
    if (crowding > kMaxCrowding * double(x_.size()) + 1e4)
        throw AirCrowded("the air crowded into few cells (" +
                         std::to_string(std::llround(crowding / double(x_.size()))) +
                         " particles a cell on average, at most " + std::to_string(kMaxCrowding) + ")");
    for (std::size_t c = 0; c < cells; ++c) cell_start_[c + 1] += cell_start_[c];
    order_.assign(x_.size(), 0);
    sorted_x_.resize(x_.size());
    std::vector<std::uint32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
    for (std::uint32_t i = 0; i < x_.size(); ++i) {
        const std::uint32_t at = fill[cell_of[i]]++;
        order_[at] = i;
        sorted_x_[at] = x_[i];
    }
    // the particles themselves move into cell order, so neighbours sit close in memory (air
    // particles have no identity a caller could hold on to)
    std::vector<glm::dvec3> v(x_.size());
    for (std::size_t k = 0; k < x_.size(); ++k) v[k] = v_[order_[k]];
    v_.swap(v);
    x_ = sorted_x_;
    for (std::uint32_t k = 0; k < order_.size(); ++k) order_[k] = k; // for_neighbours relies on it
    xf_.resize(x_.size());
    for (std::size_t k = 0; k < x_.size(); ++k) xf_[k] = glm::vec3(x_[k]);
}

template <class F> void Fluid::for_neighbours(const glm::dvec3& p, double radius, F&& f) const {
    // every cell within `radius` of p's cell; a row of cells (fixed y and z) is one run of the
    // cell-sorted arrays. (Trimming each row to the ball costs more than the candidates it saves.)
    const double cell = s_.support / 2;
    const int reach = static_cast<int>(std::ceil(radius / cell));
    // a cell beyond the grid by more than `reach` sees the same (no) cells as one just past it
    glm::ivec3 c = cell_index((p - lo_) / cell, glm::ivec3(-reach - 1), n_ + reach);
    const int x0 = std::max(c.x - reach, 0), x1 = std::min(c.x + reach, n_.x - 1);
    if (x0 > x1) return;
    for (int z = std::max(c.z - reach, 0); z <= std::min(c.z + reach, n_.z - 1); ++z)
        for (int y = std::max(c.y - reach, 0); y <= std::min(c.y + reach, n_.y - 1); ++y) {
            const std::size_t row = (static_cast<std::size_t>(z) * n_.y + y) * n_.x;
            for (std::uint32_t e = cell_start_[row + x0]; e < cell_start_[row + x1 + 1]; ++e)
                f(e, sorted_x_[e]);
        }
}

template <class F> void Fluid::for_mirrors(const glm::dvec3& p, F&& f) const {
    // the walls within the support on each axis (a wind axis has none: air leaving there re-enters
    // upwind); p is mirrored across every non-empty set of them, so near an edge or a corner the
    // air beyond both walls is there too
    double wall[3] = {0, 0, 0};
    int near = 0;
    for (int k = 0; k < 3; ++k) {
        if (s_.wind[k] != 0) continue;
        if (p[k] - s_.domain_lo[k] < s_.support)
            wall[k] = s_.domain_lo[k], near |= 1 << k;
        else if (s_.domain_hi[k] - p[k] < s_.support)
            wall[k] = s_.domain_hi[k], near |= 1 << k;
    }
    for (int set = near; set > 0; set = (set - 1) & near) {
        glm::dvec3 q = p;
        for (int k = 0; k < 3; ++k)
            if (set & (1 << k)) q[k] = 2 * wall[k] - p[k];
        f(q, set);
    }
}

void Fluid::gather_boundary(const World& plant) {
    // Hädrich et al.: only full-grown branch particles exchange forces with the fluid. Eq. 13: G
    // maps an offset from the particle into its support, the ellipsoid grown by h on each axis.
    boundary_.clear();
    const double h = s_.support;
    for (std::uint32_t i = 0; i < plant.size(); ++i) {
        Handle hd = plant.handle(i);
        if (!plant.alive(hd) || !plant.full_grown(hd)) continue;
        const glm::dvec3 r = plant.radii(hd);
        const glm::dmat3 R = glm::mat3_cast(plant.orientation(hd));
        glm::dmat3 D(0.0);
        D[0][0] = 1.0 / (r.x + h), D[1][1] = 1.0 / (r.y + h), D[2][2] = 1.0 / (r.z + h);
        const double volume = 4.0 / 3.0 * kPi * r.x * r.y * r.z;
        const double reach = std::max({r.x, r.y, r.z}) + h;
        boundary_.push_back(
            {i, plant.position(hd), plant.velocity(hd), R * D * glm::transpose(R), volume, reach});
    }
}

void Fluid::compute_densities(const World* plant) {
    const double hh = s_.support;
    poly6_c_ = poly6_coefficient(hh);
    grad_c_ = gradient_coefficient(hh);
    build_grid();
    if (plant)
        gather_boundary(*plant);
    else
        boundary_.clear();
    const double h = s_.support, m = mass_, h2 = h * h;
    // Neighbour lists (within h, not itself), kNeighbours slots per particle; a particle with
    // more (air squeezed hard) searches again where its list is needed. One pass on one thread
    // visits each pair once, from a half stencil: the rows of cells after the particle's own row
    // and, in its own row, the particles after it (the particles are in cell order). Doing it
    // once halves the distance tests of the densities; doing it on one thread keeps the sums'
    // order, and so the results, the same for every thread count.
    const std::size_t n = x_.size();
    const double cell = h / 2;
    const float reject = static_cast<float>(h2) * 1.001f; // single precision rejects, double decides
    nbr_count_.assign(n, 0);
    nbr_.resize(n * kNeighbours);
    std::vector<double>& sum = rho_;
    sum.assign(n, 0.0);
    auto link = [&](std::uint32_t i, std::uint32_t j) {
        if (nbr_count_[i] < kNeighbours) nbr_[static_cast<std::size_t>(i) * kNeighbours + nbr_count_[i]] = j;
        ++nbr_count_[i];
    };
    for (std::uint32_t i = 0; i < n; ++i) {
        const glm::dvec3 xi = x_[i];
        const glm::vec3 xif = xf_[i];
        const glm::ivec3 c = cell_index((xi - lo_) / cell, glm::ivec3(0), n_ - 1);
        const int x0 = std::max(c.x - 2, 0), x1 = std::min(c.x + 2, n_.x - 1);
        for (int z = c.z; z <= std::min(c.z + 2, n_.z - 1); ++z)
            for (int y = z == c.z ? c.y : std::max(c.y - 2, 0); y <= std::min(c.y + 2, n_.y - 1); ++y) {
                const std::size_t row = (static_cast<std::size_t>(z) * n_.y + y) * n_.x;
                const std::uint32_t begin = z == c.z && y == c.y ? i + 1 : cell_start_[row + x0];
                for (std::uint32_t j = begin; j < cell_start_[row + x1 + 1]; ++j) {
                    const glm::vec3 df = xif - xf_[j];
                    if (glm::dot(df, df) > reject) continue;
                    const glm::dvec3 d = xi - x_[j];
                    const double r2 = glm::dot(d, d);
                    if (r2 >= h2) continue;
                    const double w = h2 - r2, w3 = w * w * w;
                    sum[i] += w3;
                    sum[j] += w3;
                    link(i, j);
                    link(j, i);
                }
            }
    }
    parallel_ranges(n, s_.threads, 1024, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
            const std::uint32_t count = nbr_count_[i];
            const std::uint32_t* list = nbr_.data() + i * kNeighbours;
            double rho = sum[i] + h2 * h2 * h2; // and itself, at distance 0
            // the walls: the air mirrored across a wall within reach stands in for the missing
            // neighbours, so air at a wall is not thinner than inside. A particle within h of
            // i's mirror q is within h of i too (reflection only moves it away), so i and its
            // list hold every candidate.
            for_mirrors(x_[i], [&](const glm::dvec3& q, int) {
                auto add = [&](std::size_t j) {
                    glm::dvec3 d = q - x_[j];
                    double r2 = glm::dot(d, d);
                    if (r2 < h2) {
                        double w = h2 - r2;
                        rho += w * w * w;
                    }
                };
                add(i);
                if (count <= kNeighbours)
                    for (std::uint32_t t = 0; t < count; ++t) add(list[t]);
                else
                    for_neighbours(q, h, [&](std::uint32_t j, const glm::dvec3&) {
                        if (j != i) add(j);
                    });
            });
            rho_[i] = rho * m * poly6_c_;
        }
    });
    // plant particles as boundary: Eq. 12 with their volume and rest_density
    for (const Boundary& bd : boundary_)
        for_neighbours(bd.x, bd.reach, [&](std::uint32_t j, const glm::dvec3& xj) {
            const glm::dvec3 off = xj - bd.x;
            if (glm::dot(off, off) >= bd.reach * bd.reach) return;
            glm::dvec3 eta = bd.G * off; // Eq. 13
            double q = glm::length(eta);
            if (q < 1) {
                const double w = h * h * (1 - q * q);
                rho_[j] += s_.rest_density * bd.volume * poly6_c_ * w * w * w * s_.coupling;
            }
        });
    // air is a gas: p = k rho (Desbrun and Gascuel's equation of state, which Müller et al. 2003
    // shift by rho_0 for liquids). The shifted form lets pressure go negative, and air short of
    // neighbours (at the edge of a gap) then holds together like a liquid instead of filling the
    // room. With mirrored walls the uniform state is at rest density and in balance.
    vol_.resize(x_.size());
    for (std::size_t i = 0; i < x_.size(); ++i) {
        p_[i] = s_.stiffness * rho_[i];
        vol_[i] = mass_ / rho_[i]; // m_j / rho_j, the particle's volume in Eq. 12
    }
}

void Fluid::step(World* plant) {
    const double h = s_.support, m = mass_, dt = s_.dt;
    compute_densities(plant);
    // Eq. 11: a = (-grad p + mu lap v) / rho, pressure symmetrised as in Müller et al. 2003
    parallel_ranges(x_.size(), s_.threads, 1024, [&](std::size_t b, std::size_t e) {
        for (std::size_t k = b; k < e; ++k) {
            const std::uint32_t i = order_[k];
            glm::dvec3 f(0.0);
            const double h2 = h * h;
            auto pair = [&](std::uint32_t j) {
                glm::dvec3 d = x_[i] - x_[j];
                double r2 = glm::dot(d, d);
                if (r2 >= h2 || r2 < 1e-24) return; // outside, or itself
                double r = std::sqrt(r2), hr = h - r, inv = vol_[j];
                // spiky gradient (Müller et al. Eq. 21) and viscosity Laplacian (Eq. 22)
                f += d * ((p_[i] + p_[j]) * 0.5 * inv * grad_c_ * hr * hr / r);
                f += (v_[j] - v_[i]) * (s_.viscosity * inv * grad_c_ * hr);
            };
            if (nbr_count_[i] <= kNeighbours) {
                const std::uint32_t* list = nbr_.data() + static_cast<std::size_t>(i) * kNeighbours;
                for (std::uint32_t c = 0; c < nbr_count_[i]; ++c) pair(list[c]);
            } else {
                for_neighbours(x_[i], h, [&](std::uint32_t j, const glm::dvec3&) { pair(j); });
            }
            // the mirrored air pushes back from the walls: the mirror image of j seen from i is
            // at the distance of q (i mirrored) from j, in the direction of q - x_j mirrored
            for_mirrors(x_[i], [&](const glm::dvec3& q, int axes) {
                auto mirrored = [&](std::uint32_t j) {
                    glm::dvec3 d = q - x_[j];
                    double r2 = glm::dot(d, d);
                    if (r2 >= h2 || r2 < 1e-24) return;
                    double r = std::sqrt(r2), hr = h - r;
                    for (int a = 0; a < 3; ++a)
                        if (axes & (1 << a)) d[a] = -d[a];
                    f += d * ((p_[i] + p_[j]) * 0.5 * vol_[j] * grad_c_ * hr * hr / r);
                };
                mirrored(i); // its own image too
                if (nbr_count_[i] <= kNeighbours) {
                    const std::uint32_t* list = nbr_.data() + static_cast<std::size_t>(i) * kNeighbours;
                    for (std::uint32_t t = 0; t < nbr_count_[i]; ++t) mirrored(list[t]);
                } else {
                    for_neighbours(q, h, [&](std::uint32_t j, const glm::dvec3&) {
                        if (j != i) mirrored(j);
                    });
                }
            });
            a_[i] = f / rho_[i];
        }
    });
    // two-way coupling with the plant's full-grown particles
    if (plant) {
        plant_force_.assign(boundary_.size(), glm::dvec3(0.0));
        for (std::size_t k = 0; k < boundary_.size(); ++k) {
            const Boundary& bd = boundary_[k];
            const double psi = s_.rest_density * bd.volume * s_.coupling; // its "mass" as a boundary
            for_neighbours(bd.x, bd.reach, [&](std::uint32_t j, const glm::dvec3& xj) {
                glm::dvec3 off = xj - bd.x;
                if (glm::dot(off, off) >= bd.reach * bd.reach) return;
                glm::dvec3 eta = bd.G * off;
                double q = glm::length(eta);
                if (q >= 1 || q < 1e-12) return;
                glm::dvec3 dir = glm::normalize(glm::transpose(bd.G) * eta);
                // pressure pushes the air out of the branch, drag carries the branch along
                const double hr = h - q * h;
                glm::dvec3 f = dir * (psi * p_[j] / rho_[j] * grad_c_ * hr * hr);
                f += (bd.v - v_[j]) * (s_.viscosity * psi / rho_[j] * grad_c_ * hr);
                a_[j] += f / rho_[j];
                plant_force_[k] -= f * (m / rho_[j]);
            });
        }
        for (std::size_t k = 0; k < boundary_.size(); ++k) {
            Handle hd = plant->handle(boundary_[k].particle);
            plant->add_external(hd, plant_force_[k] / plant->mass(hd));
        }
    }
    // symplectic Euler; walls of the domain, except that air leaving downwind re-enters upwind
    const glm::dvec3 lo = s_.domain_lo, hi = s_.domain_hi;
    const bool windy = glm::length(s_.wind) > 0;
    for (std::size_t i = 0; i < x_.size(); ++i) {
        // the fan: a wind draws the air toward its velocity (and the air keeps moving once it
        // is switched off, until viscosity and the walls stop it)
        if (windy) a_[i] += (s_.wind - v_[i]) * s_.drive;
        for (const Emitter& e : s_.emitters) {
            const glm::dvec3 d = x_[i] - e.point;
            const double r2 = glm::dot(d, d);
            if (!(e.radius > 0) || r2 >= e.radius * e.radius) continue;
            // weight 1 at the centre, 0 at the edge
            a_[i] += (e.velocity - v_[i]) * (s_.emitter_drive * (1.0 - std::sqrt(r2) / e.radius));
        }
        v_[i] += a_[i] * dt;
        x_[i] += v_[i] * dt;
        for (int k = 0; k < 3; ++k) {
            const double extent = hi[k] - lo[k];
            if (windy && s_.wind[k] != 0 && (x_[i][k] > hi[k] || x_[i][k] < lo[k])) {
                x_[i][k] = x_[i][k] > hi[k] ? x_[i][k] - extent : x_[i][k] + extent; // re-enter upwind
                v_[i] = s_.wind;
                continue;
            }
            if (x_[i][k] < lo[k]) x_[i][k] = lo[k], v_[i][k] = std::max(v_[i][k], 0.0) * 0.5;
            if (x_[i][k] > hi[k]) x_[i][k] = hi[k], v_[i][k] = std::min(v_[i][k], 0.0) * 0.5;
        }
    }
}

} // namespace plant::physics
