#pragma once
// Last stage of the MARS processor: the exact search over the source quadtree.

#include <cstdint>

#include "marsala/core/detail/mars_common.hpp"
#include "marsala/core/detail/mars_source_tree.hpp"

namespace marsala::detail {

/// Raises lower [m] to max over the tree's sources of h(q) - kcs |p - q| (within pb.tol), for
/// every target p, given that lower already holds every source within kLocalRadius2. With `wanted` (one 64-bit mask
/// per kBlock x kBlock block of targets, row-major over blocks, bit (row % kBlock) * kBlock + col % kBlock), only the
/// targets it marks: each target's value is the same bits as in the whole search (a target's search reads only its
/// own limit), the others keep their lower bound.
void search_sources(const Problem& pb, const SourceTree& tree, double* lower, const std::uint64_t* wanted = nullptr);

}  // namespace marsala::detail
