// bsplineMorph: OpenFOAM-free multilevel B-spline core (internal header)
// Spatial order: points sorted along a space-filling curve (Morton order of
// their level-0 local coordinates), so that points next in order are near in
// space and their stencils share tiles (locality for the lattices).
#ifndef MBA_SPATIALORDER_HPP
#define MBA_SPATIALORDER_HPP

#include "geometry.hpp"

#include <cstdint>
#include <vector>

namespace mba {

/// Indices of the points of x in Morton order; select: per point 0/1, the
/// points to order (nullptr: all)
template <int D>
std::vector<std::uint32_t> spatialOrder(pointsView<D> x, const domain<D>& dom,
                                        const std::vector<std::uint8_t>* select);

/// Whether the points' own order is about as short a path through them as
/// the given order (mesh points mostly come numbered with locality already)
template <int D>
bool ownOrderIsAsShort(pointsView<D> x, const std::vector<std::uint32_t>& order);

} // namespace mba
#endif
