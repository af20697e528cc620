// A hand grabbing a branch and pulling it (Hädrich et al. 2017, Fig. 7 (c) and section 5.1:
// "branches can be grabbed"). The grabbed particle moves toward the hand at a bounded pace, and
// the stem between it and its root follows within its length, as an inextensible string does:
// an ancestor moves only while its link to the part already moved is taut, straight toward it.
// The stem comes off its supports (an anchor lets go once its particle is past the anchor's
// release distance, pull_to_anchors) instead of stretching between the hand and the anchors, which
// a held particle alone did (docs/physics.md, "Dragging and breaking").
#include "plant/physics/world.hpp"

#include "cells.hpp"

#include <algorithm>
#include <cmath>

namespace plant::physics {

namespace {

// `to` moved onto the sphere of radius `length` about `from` when it lies beyond it
glm::dvec3 within(const glm::dvec3& from, const glm::dvec3& to, double length) {
    const glm::dvec3 d = to - from;
    const double l = glm::length(d);
    return l > length && l > 0 ? from + d * (length / l) : to;
}

} // namespace

void World::grab(Handle h, const glm::dvec3& target, double reach) {
    if (!alive(h) || fixed_[h.index] || !finite(target) || !(reach > 0)) return;
    // the chain from the grabbed particle down to its root: chain[0] = h, chain[k + 1] the parent
    // of chain[k] (a parent's index is below its children's, so it ends within size() links)
    std::vector<std::uint32_t> chain{h.index};
    while (parent_[chain.back()] != kNone && chain.size() <= x_.size())
        chain.push_back(parent_[chain.back()]);
    auto rest = [&](std::size_t k) { // the rest length of chain[k]'s link to chain[k + 1]
        return glm::length(rest_x_[chain[k]] - rest_x_[chain[k + 1]]);
    };
    auto radius = [&](std::size_t k) {
        return std::min({radii_[chain[k]].x, radii_[chain[k]].y, radii_[chain[k]].z});
    };
    // the hand moves at most `reach` this step, clear of the obstacles
    std::vector<glm::dvec3> y{x_[h.index]};
    y[0] = clear_segment_end(x_[h.index], within(x_[h.index], target, reach), radius(0));
    // toward the root: each ancestor whose link is taut comes along, straight toward the part
    // moved; a slack link, or a fixed particle (the root), stops it
    std::size_t moved = 1;
    bool to_root = false;
    for (; moved < chain.size(); ++moved) {
        const std::uint32_t j = chain[moved];
        if (fixed_[j]) {
            to_root = true;
            break;
        }
        const double l = rest(moved - 1);
        if (glm::length(x_[j] - y.back()) <= l) break;
        y.push_back(clear_segment_end(y.back(), within(y.back(), x_[j], l), radius(moved)));
    }
    // a hand beyond the stem's length from its root: the stem straightens from the root toward
    // it, and the grabbed particle stops where the stem ends
    if (to_root && moved < chain.size()) {
        glm::dvec3 from = x_[chain[moved]];
        for (std::size_t k = moved; k-- > 0;) {
            y[k] = clear_segment_end(from, within(from, y[k], rest(k)), radius(k));
            from = y[k];
        }
    }
    // the moved particles are held there through the step, as pull() holds one
    for (std::size_t k = 0; k < y.size(); ++k) {
        x_[chain[k]] = y[k];
        pulls_.push_back({chain[k], y[k]});
    }
}

} // namespace plant::physics
