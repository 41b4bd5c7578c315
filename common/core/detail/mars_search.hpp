#pragma once
// Last stage of the MARS processor: the exact search over the source quadtree.

#include "marsala/core/detail/mars_common.hpp"
#include "marsala/core/detail/mars_source_tree.hpp"

namespace marsala::detail {

/// Raises lower [m] to max over the tree's sources of h(q) - kcs |p - q| (within pb.tol), for
/// every target p, given that lower already holds every source within kLocalRadius2.
void search_sources(const Problem& pb, const SourceTree& tree, double* lower);

}  // namespace marsala::detail
