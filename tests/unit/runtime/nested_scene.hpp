// A hand-made nested scene for the export tests (unit tests and tests/gltf/nested_scene.cpp): a
// row of two trees, each tree a trunk with 4 long and 4 short branches around it, each branch a
// stick with leaves (12 on a long branch, 6 on a short one, the same leaf shape), the way a willow
// places weeping branches at two levels of detail. The row also places an "odd" box three times:
// rigidly, with a shear and mirrored.
#pragma once

#include "plant/scene.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include <memory>

namespace plant::test {

// A box from -h to h, 12 triangles, faces sharing no vertices, in one material.
inline MeshPart box_part(glm::vec3 h, std::uint32_t material) {
    MeshPart m;
    for (int axis = 0; axis < 3; ++axis)
        for (int side = -1; side <= 1; side += 2) {
            glm::vec3 n(0.0f);
            n[axis] = float(side);
            const int u = (axis + 1) % 3, v = (axis + 2) % 3;
            const auto base = static_cast<std::uint32_t>(m.positions.size());
            for (int k = 0; k < 4; ++k) {
                glm::vec3 p(0.0f);
                p[axis] = side * h[axis];
                p[u] = ((k & 1) ? 1.0f : -1.0f) * h[u];
                p[v] = ((k & 2) ? 1.0f : -1.0f) * h[v];
                m.positions.push_back(p);
                m.normals.push_back(n);
                m.uvs.emplace_back(k & 1, (k & 2) >> 1);
            }
            if (side > 0)
                m.indices.insert(m.indices.end(), {base, base + 1, base + 3, base, base + 3, base + 2});
            else
                m.indices.insert(m.indices.end(), {base, base + 3, base + 1, base, base + 2, base + 3});
        }
    m.primitives.push_back(Primitive{0, static_cast<std::uint32_t>(m.indices.size()), material});
    return m;
}

// A flat leaf in the xy plane, pointing along +y, two-sided.
inline MeshPart leaf_part(std::uint32_t material) {
    MeshPart m;
    const glm::vec3 pts[4] = {{0, 0, 0}, {0.2f, 0.5f, 0}, {0, 1, 0}, {-0.2f, 0.5f, 0}};
    for (int side = 0; side < 2; ++side) {
        const auto base = static_cast<std::uint32_t>(m.positions.size());
        for (const glm::vec3& p : pts) {
            m.positions.push_back(p);
            m.normals.emplace_back(0, 0, side == 0 ? 1 : -1);
            m.uvs.emplace_back(p.x + 0.5f, p.y);
        }
        if (side == 0)
            m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
        else
            m.indices.insert(m.indices.end(), {base, base + 2, base + 1, base, base + 3, base + 2});
    }
    m.primitives.push_back(Primitive{0, static_cast<std::uint32_t>(m.indices.size()), material});
    return m;
}

// A branch along +y of `leaves` leaves, each turned about the branch and tilted down.
inline std::shared_ptr<Scene> branch_scene(int leaves) {
    auto s = std::make_shared<Scene>();
    s->materials = {Material{{0.4f, 0.3f, 0.2f}}, Material{{0.3f, 0.6f, 0.2f}}};
    s->tubes = box_part({0.05f, 0.5f * float(leaves), 0.05f}, 0);
    for (auto& p : s->tubes.positions) p.y += 0.5f * float(leaves);
    s->prototypes.push_back(leaf_part(1));
    s->prototype_names.push_back("leaf");
    for (int k = 0; k < leaves; ++k) {
        glm::mat4 m = glm::translate(glm::mat4(1.0f), glm::vec3(0, float(k) + 0.5f, 0));
        m = glm::rotate(m, glm::radians(137.5f * float(k)), glm::vec3(0, 1, 0));
        m = glm::rotate(m, glm::radians(120.0f), glm::vec3(1, 0, 0));
        m = glm::scale(m, glm::vec3(0.8f + 0.02f * float(k)));
        s->instances.push_back(Instance{0, m});
    }
    s->update_bounds();
    return s;
}

// A trunk with 4 long (12 leaves) and 4 short (6 leaves) branches.
inline std::shared_ptr<Scene> tree_scene() {
    auto s = std::make_shared<Scene>();
    s->materials = {Material{{0.35f, 0.25f, 0.15f}}};
    s->tubes = box_part({0.3f, 5.0f, 0.3f}, 0);
    for (auto& p : s->tubes.positions) p.y += 5.0f;
    s->scene_prototypes = {branch_scene(12), branch_scene(6)};
    s->scene_prototype_names = {"long", "short"};
    for (int k = 0; k < 8; ++k) {
        glm::mat4 m = glm::translate(glm::mat4(1.0f), glm::vec3(0, 4.0f + 0.7f * float(k), 0));
        m = glm::rotate(m, glm::radians(90.0f * float(k) + 10.0f), glm::vec3(0, 1, 0));
        m = glm::rotate(m, glm::radians(-50.0f), glm::vec3(0, 0, 1));
        m = glm::scale(m, glm::vec3(0.5f));
        s->scene_instances.push_back(Instance{static_cast<std::uint32_t>(k % 2), m});
    }
    s->update_bounds();
    return s;
}

// Leaves: 2 trees x (4 x 12 + 4 x 6) = 144.
constexpr int kNestedLeaves = 144;

inline Scene nested_scene() {
    Scene s;
    s.materials = {Material{{0.5f, 0.5f, 0.5f}}};
    s.tubes = box_part({10.0f, 0.05f, 3.0f}, 0); // the ground
    s.prototypes.push_back(box_part({0.5f, 0.5f, 0.5f}, 0));
    s.prototype_names.push_back("odd");
    const glm::mat4 rigid =
        glm::rotate(glm::translate(glm::mat4(1.0f), glm::vec3(-8, 1, 0)), 0.3f, glm::vec3(0, 0, 1));
    glm::mat4 shear = glm::translate(glm::mat4(1.0f), glm::vec3(8, 1, 0));
    shear[1][0] = 0.5f; // x grows with y
    const glm::mat4 mirror =
        glm::scale(glm::translate(glm::mat4(1.0f), glm::vec3(0, 1, 2)), glm::vec3(-1, 1, 1));
    s.instances = {Instance{0, rigid}, Instance{0, shear}, Instance{0, mirror}};
    s.scene_prototypes = {tree_scene()};
    s.scene_prototype_names = {"tree"};
    s.scene_instances = {
        Instance{0, glm::translate(glm::mat4(1.0f), glm::vec3(-4, 0, 0))},
        Instance{0, glm::scale(glm::rotate(glm::translate(glm::mat4(1.0f), glm::vec3(4, 0, 0)), 1.0f,
                                           glm::vec3(0, 1, 0)),
                               glm::vec3(1.5f))}};
    s.update_bounds();
    return s;
}

// A forest: `trees` placements of one tree that places `leaves` leaves (a trunk box and leaves
// placed around it).
inline Scene forest_scene(int trees, int leaves) {
    auto tree = std::make_shared<Scene>();
    tree->materials = {Material{glm::vec3(0.4f, 0.3f, 0.2f)}, Material{glm::vec3(0.2f, 0.6f, 0.2f)}};
    tree->tubes = box_part(glm::vec3(0.1f, 2.0f, 0.1f), 0);
    tree->prototypes = {leaf_part(1)};
    tree->prototype_names = {"leaf"};
    for (int k = 0; k < leaves; ++k) {
        glm::mat4 m = glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 1.0f + 0.001f * float(k), 0.0f));
        m = glm::rotate(m, 0.37f * float(k), glm::vec3(0, 1, 0));
        tree->instances.push_back(Instance{0, m});
    }
    tree->update_bounds();
    Scene s;
    s.materials = {Material{}};
    s.scene_prototypes = {tree};
    s.scene_prototype_names = {"tree"};
    for (int t = 0; t < trees; ++t) {
        glm::mat4 m =
            glm::translate(glm::mat4(1.0f), glm::vec3(3.0f * float(t % 10), 0.0f, 3.0f * float(t / 10)));
        m = glm::scale(glm::rotate(m, 0.5f * float(t), glm::vec3(0, 1, 0)),
                       glm::vec3(1.0f + 0.01f * float(t)));
        s.scene_instances.push_back(Instance{0, m});
    }
    s.update_bounds();
    return s;
}

} // namespace plant::test
