// The parse tree's node type (parser.cpp), with its own allocation.
#pragma once

#include <tao/pegtl/contrib/parse_tree.hpp>

#include <cstddef>

namespace plant {

// A parse-tree node. PEGTL gives a node to every rule that may hold a selected one while it is
// tried, and drops it when the rule fails or is folded away, so a long file makes and frees
// millions (a number passes eight precedence levels). They come from a free list of the thread's
// instead of malloc (parse_node.cpp): `plant check` on 100,001 key arguments
// (tests/hostile/t23_05_attractor_count.plant) took 2.8 s, over a third of it in malloc and free,
// and takes 1.8 s (medians of five runs each, alternated, on a 2.0 GHz host).
struct Node : tao::pegtl::parse_tree::basic_node<Node> {
    static void* operator new(std::size_t size);
    static void operator delete(void* p, std::size_t size) noexcept;
};

} // namespace plant
