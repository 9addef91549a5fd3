// bsplineMorph: OpenFOAM-free multilevel B-spline core (internal header)
// A plain lattice: the nodes of an index box stored in one array, untiled,
// the last direction fastest, nc values a node (the flat lattice of the
// evaluation, a stencil's nodes copied into a block). The stencil kernel
// that reads one: a stencil row along the last direction is 4 contiguous
// nodes, so rows are summed as whole vectors.
#ifndef MBA_PLAINLATTICE_HPP
#define MBA_PLAINLATTICE_HPP

#include "stencilKernels.hpp"

namespace mba {

/// Nodes of box b
template <int D>
double boxNodes(const indexBox<D>& b)
{
    double n = 1;
    for (int d = 0; d < D; ++d) n *= double(b.hi[d] - b.lo[d] + 1);
    return n;
}

/// Node i of a plain lattice over the nodes of box b (the last direction
/// fastest, nc values a node)
template <int D>
inline const double* flatNode(const double* G, const indexBox<D>& b, const index<D>& i, int nc)
{
    return G + boxIndex<D>(b, i)*nc;
}

/// Adds to out[0..NC) the value at a stencil of a plain 3D lattice whose
/// first node is p0 (n1, n2: the box's nodes along the second and last
/// directions; the last direction fastest, NC values a node): the 4 nodes
/// along the last direction are contiguous, so the 16 rows, weighted by
/// rowW(a, c) (the product of the first two directions' weights), are summed
/// first, as vectors of W doubles, into two accumulators (alternate rows:
/// two independent add chains), and the sum then weighted by wLast
template <int NC, int W, class RowW>
inline __attribute__((always_inline)) void flatRows(const double* p0, std::int64_t n1, std::int64_t n2,
                                                    RowW&& rowW, const double* wLast, double* out)
{
    detail::vrow<4*NC, W> r[2] = {};
    for (int a = 0; a < 4; ++a)
        for (int c = 0; c < 4; ++c) detail::axpy<4*NC, W>(r[c & 1], rowW(a, c), p0 + (a*n1 + c)*n2*NC);
    detail::add(r[0], r[1]);
    detail::addRowSum<NC, W>(r[0], wLast, out);
}

/// Adds the value at a stencil of a plain lattice (nodes of box b, the last
/// direction fastest, NC values per node), as flatRows
template <int NC, int W>
inline __attribute__((always_inline)) void flatStencil(const double* G, const indexBox<3>& b,
                                                       const stencil<3>& st, double* out)
{
    flatRows<NC, W>(flatNode<3>(G, b, st.base, NC), b.hi[1] - b.lo[1] + 1, b.hi[2] - b.lo[2] + 1,
                    [&](int a, int c) { return st.w[0][a]*st.w[1][c]; }, st.w[2], out);
}

template <int NC, int W>
inline __attribute__((always_inline)) void flatStencil(const double* G, const indexBox<2>& b,
                                                       const stencil<2>& st, double* out)
{
    const std::int64_t n1 = b.hi[1] - b.lo[1] + 1;
    const double* p0 = flatNode<2>(G, b, st.base, NC);
    detail::vrow<4*NC, W> r[2] = {};
    for (int a = 0; a < 4; ++a) detail::axpy<4*NC, W>(r[a & 1], st.w[0][a], p0 + a*n1*NC);
    detail::add(r[0], r[1]);
    detail::addRowSum<NC, W>(r[0], st.w[1], out);
}

} // namespace mba
#endif
