// One instance's derivation for one placement (plant/instances.hpp).
#include "plant/instances.hpp"

#include "plant/random.hpp"

#include <bit>
#include <stdexcept>

namespace plant {

std::uint64_t instance_seed(std::uint64_t outer_seed, int index, std::span<const double> args) {
    std::uint64_t h = mix64(outer_seed + 0x9e3779b97f4a7c15ULL);
    h = mix64(h ^ (static_cast<std::uint64_t>(index) * 0xd1b54a32d192ed03ULL));
    for (double a : args) h = mix64(h ^ std::bit_cast<std::uint64_t>(a == 0 ? 0.0 : a)); // -0 is 0
    return h >> 2; // within the range a grammar's `seed` may take
}

std::size_t instance_arg_width(const InstanceDef& def) {
    std::size_t n = 0;
    for (ValueType t : def.param_types) n += static_cast<std::size_t>(value_width(t));
    return n;
}

Derivation instance_derivation(const InstanceDef& def, int index, std::span<const double> args,
                               double view_depth, std::uint64_t outer_seed, DeriveOptions options) {
    if (!def.program) throw std::invalid_argument("instance '" + def.name + "' has no compiled body");
    if (args.size() != instance_arg_width(def) || def.param_slots.size() != def.param_types.size())
        throw std::invalid_argument("instance '" + def.name + "' given the wrong number of arguments");
    const Program& p = *def.program;
    if (p.setting(ast::SettingKey::Seed).empty()) options.seed = instance_seed(outer_seed, index, args);
    Derivation d(p, std::move(options));
    std::vector<double>& g = d.globals();
    std::size_t k = 0;
    for (std::size_t i = 0; i < def.param_slots.size(); ++i)
        for (int w = 0; w < value_width(def.param_types[i]); ++w) g.at(def.param_slots[i] + w) = args[k++];
    if (auto it = p.global_index.find("view_depth"); it != p.global_index.end())
        g.at(p.globals[it->second].slot) = view_depth;
    return d;
}

} // namespace plant
