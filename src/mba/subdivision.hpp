// bsplineMorph: OpenFOAM-free multilevel B-spline core (internal header)
// Uniform cubic B-spline subdivision: the coefficients of one level refined
// to the next (half the cell edge) represent the same function exactly, so
// the coarse levels can be summed on the lattice of a finer one.
#ifndef MBA_SUBDIVISION_HPP
#define MBA_SUBDIVISION_HPP

#include "geometry.hpp"
#include "hugePages.hpp"

namespace mba {

/// Values G (nc per node, the last direction fastest) on the node box cb of
/// one level, refined to the next level on the node box fb, one direction at
/// a time (the parents of fb's nodes that the stencils of points inside the
/// boxes use lie in cb). G holds at least cb's values (more are ignored),
/// on return at least fb's; T: scratch, swapped with G. Neither array
/// shrinks, so that refining the same boxes again writes no zeros first.
template <int D>
void refine(hugeVector<double>& G, const indexBox<D>& cb, const indexBox<D>& fb, int nc, hugeVector<double>& T);

/// v holds at least n values (kept when it holds more: an array that refine()
/// works in grows once, and is not filled with zeros again in every fit)
inline void holdAtLeast(hugeVector<double>& v, std::size_t n)
{
    if (v.size() < n) v.resize(n);
}

} // namespace mba
#endif
