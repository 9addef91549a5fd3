// bsplineMorph: OpenFOAM-free multilevel B-spline core (internal header)
// A trend under the levels (multilevel::fit with a trend): a cubic B-spline
// given by its coefficients at every node of one level's lattice over the
// whole domain. The fit subtracts it at the control points before the
// affine start and the levels; every evaluation adds it back (the flat
// evaluator folds it into its lattice at its level, refined exactly with
// the coarser levels).
#ifndef MBA_TRENDLATTICE_HPP
#define MBA_TRENDLATTICE_HPP

#include "plainLattice.hpp"

#include <cmath>
#include <vector>

namespace mba {

template <int D>
struct trendLattice
{
    int level = -1;                 ///< -1: no trend
    indexBox<D> box;                ///< the level's nodes (nodeBox)
    std::vector<double> phi;        ///< coefficients, nc a node, the last direction fastest

    bool active() const { return level >= 0; }

    /// Every node of level k over the domain: node j at x = lo + (j - 1) h_k,
    /// j = 0 .. n0 2^k + 2 (the stencils of all points in the domain); throws
    /// std::invalid_argument for k outside [0, 16]
    static indexBox<D> nodeBox(const domain<D>& dom, int k)
    {
        precondition(k >= 0 && k <= 16, "mba: the trend's level must be in [0, 16], got " + std::to_string(k));
        indexBox<D> b;
        for (int d = 0; d < D; ++d)
        {
            b.lo[d] = 0;
            b.hi[d] = dom.n0[d]*(std::int64_t(1) << k) + 2;
        }
        return b;
    }

    /// Adds the trend at the point with level-0 local coordinates u0 to out[0..nc)
    void addAt(const point<D>& u0, int nc, double* out) const
    {
        if (!active()) return;
        const stencil<D> st = levelStencil<D>(u0, std::ldexp(1.0, level));
        switch (nc)
        {
            case 1: flatStencil<1, 2>(phi.data(), box, st, out); break;
            case 2: flatStencil<2, 2>(phi.data(), box, st, out); break;
            default: flatStencil<3, 2>(phi.data(), box, st, out);
        }
    }
};

} // namespace mba
#endif
