// What the mesher hands to the exporters: flat triangle buffers in world space for the tubes,
// organ prototypes meshed once, and their placements; and whole scenes placed as prototypes
// (instanced sub-plants), which the exporters flatten. y is up (glTF's convention).
#pragma once

#include <glm/glm.hpp>

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

namespace plant {

// An image a material is drawn with (docs/language.md, textures): the file's bytes as the grammar
// named them, PNG or JPEG.
struct Texture {
    std::string name;
    std::string mime_type;                    // "image/png" or "image/jpeg"
    std::shared_ptr<const std::string> bytes; // shared with the program and other scenes
};

struct Material {
    glm::vec3 color{0.45f, 0.32f, 0.2f}; // linear RGB, 0..1
    int texture = -1; // an index in Scene::textures, -1 for none; the image replaces the colour
};

// Triangles of one material: indices[first, first + count) of the part's index buffer.
struct Primitive {
    std::uint32_t first = 0;
    std::uint32_t count = 0;
    std::uint32_t material = 0;
};

// Flat vertex and index buffers (about 30 bytes a triangle): positions, unit normals and
// texture coordinates per vertex, three indices per triangle.
struct MeshPart {
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;
    std::vector<glm::vec2> uvs;
    std::vector<std::uint32_t> indices;
    std::vector<Primitive> primitives;
    std::size_t triangle_count() const { return indices.size() / 3; }
    bool empty() const { return indices.empty(); }
};

// One placement of a prototype: a rigid transform with uniform scale.
struct Instance {
    std::uint32_t prototype = 0;
    glm::mat4 transform{1.0f};
};

// What a scene prototype was made from: an instance, its argument tuple and its view depth
// (docs/language.md, instances).
struct SceneSource {
    std::string instance;
    std::vector<double> args;
    double view_depth = 0;
};

struct Scene {
    MeshPart tubes;                   // every generalized cylinder, in world space
    std::vector<MeshPart> prototypes; // organ shapes (leaves, flowers, spheres), in their own frame
    std::vector<std::string> prototype_names;
    std::vector<Instance> instances;
    // Prototypes that are whole scenes, in their own frame with their own materials (an
    // instanced sub-plant), and their placements (Instance::prototype indexes scene_prototypes).
    std::vector<std::shared_ptr<const Scene>> scene_prototypes;
    std::vector<std::string> scene_prototype_names;
    std::vector<Instance> scene_instances;
    std::vector<SceneSource> scene_prototype_sources; // per scene prototype when build_scene made it
    std::size_t instance_derivations = 0; // instance derivations build_scene ran for it (nested ones too)
    std::vector<Material> materials;      // at least one
    std::vector<Texture> textures;        // what materials name (the program's, used or not)
    glm::vec3 bounds_min{0.0f}, bounds_max{0.0f}; // of everything, instances and placed scenes included
    void update_bounds();
    bool nested() const { return !scene_instances.empty(); }
};

// The scene with every placed scene drawn into it: each placed scene's tubes become one prototype
// and its prototypes become prototypes of the result (once per scene prototype, however often it
// is placed), placed by the composed transforms; its materials join the result's (one per
// color). Prototypes, instances and materials the scene had keep their indices, and a scene
// without placed scenes comes back unchanged. Throws std::out_of_range for a placement of a
// scene prototype that does not exist.
Scene flatten(const Scene& scene);
// The same without working out the result's bounds, which stay `scene`'s own: a box that holds
// every point drawn (tight when scene's was), for writers that do not read the bounds. Placing
// every point of every placement again is a large part of flattening a big scene.
Scene flatten_keeping_bounds(const Scene& scene);

// What `scene` draws with every placed scene drawn out, counted without drawing it: the vertices
// and triangles of its tubes and of every placement (placed scenes once per placement, at every
// level), and the placements that draw something, which are the instances flatten() makes: of
// organ prototypes, and of a placed scene's tubes when it has any, at every level.
struct DrawnSize {
    double vertices = 0, triangles = 0, placements = 0;
};
DrawnSize drawn_size(const Scene& scene);

// Gathers materials from several scenes into one: one material per colour and texture image (told
// apart by their bytes), each image added to the result's textures once. The result's own
// materials keep their indices.
class MaterialMerger {
  public:
    explicit MaterialMerger(Scene& out);
    // The result's index of material `m` of `from` (which may be the result itself).
    std::uint32_t add(const Scene& from, std::uint32_t m);

  private:
    std::uint32_t add(const Material& material, const Texture* texture);
    Scene& out_;
    std::map<std::tuple<float, float, float, const std::string*>, std::uint32_t> index_;
};

} // namespace plant
