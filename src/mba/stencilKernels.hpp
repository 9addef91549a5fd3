// bsplineMorph: OpenFOAM-free multilevel B-spline core
// The 4^D stencil kernels on a tiled lattice (lattice.hpp): the value at a
// stencil (a sweep of its rows), a point's scatter into its stencil's nodes,
// a run of points sharing a stencil, each in vectors of two doubles and, on
// x86-64 with AVX2 and FMA, of four (vectorWidth.hpp). A stencil row along
// the last direction is at most two tile rows of 4 contiguous nodes.
#ifndef MBA_STENCILKERNELS_HPP
#define MBA_STENCILKERNELS_HPP

#include "lattice.hpp"
#include "vectorWidth.hpp"

#include <type_traits>

namespace mba {

namespace detail {
typedef vec<2>::type v2d;
typedef vec<2>::unaligned v2du;

/// Rows of N doubles as vectors of W, kept in registers; per lane the same
/// arithmetic as scalar code
template <int N, int W = 2> struct vrow
{
    static_assert(N % W == 0, "rows of 4 nodes");
    typename vec<W>::type v[N/W];

    /// The row p[0..N)
    static inline __attribute__((always_inline)) vrow load(const double* p)
    {
        vrow r;
        typedef typename vec<W>::unaligned U;   // (not auto: that would drop the alignment of 8)
        const U* q = reinterpret_cast<const U*>(p);
        for (int i = 0; i < N/W; ++i) r.v[i] = q[i];
        return r;
    }

    /// Stores the row to p[0..N)
    inline __attribute__((always_inline)) void store(double* p) const
    {
        typedef typename vec<W>::unaligned U;
        U* q = reinterpret_cast<U*>(p);
        for (int i = 0; i < N/W; ++i) q[i] = v[i];
    }
};

/// a += w*b
template <int N, int W>
inline __attribute__((always_inline)) void axpy(vrow<N, W>& a, double w, const vrow<N, W>& b)
{
    for (int i = 0; i < N/W; ++i) a.v[i] += w*b.v[i];
}

/// a += w*p (p a row in memory)
template <int N, int W = 2>
inline __attribute__((always_inline)) void axpy(vrow<N, W>& a, double w, const double* p)
{
    axpy<N, W>(a, w, vrow<N, W>::load(p));
}

/// a += b
template <int N, int W>
inline __attribute__((always_inline)) void add(vrow<N, W>& a, const vrow<N, W>& b)
{
    for (int i = 0; i < N/W; ++i) a.v[i] += b.v[i];
}

/// Adds to out[0..NC) the row sum r (4 nodes of NC values along the last
/// direction) weighted by the stencil's last-direction weights w
template <int NC, int W = 2>
inline __attribute__((always_inline)) void addRowSum(const vrow<4*NC, W>& r, const double* w, double* out)
{
    double s[4*NC];
    r.store(s);
    for (int c = 0; c < 4; ++c)
        for (int k = 0; k < NC; ++k) out[k] += w[c]*s[c*NC + k];
}

/// The rows of a stencil along its last direction: f(t, n, w) for each of
/// its 4^(D-1) rows, with t the entry in stencilTiles of the tile that holds
/// the row's first nodes (the next tile along the last direction is t + 1),
/// n the node in that tile where the row's tile-row starts (last coordinate
/// 0: a row of a tile is 4 contiguous nodes) and w the product of the row's
/// weights in the other directions
template <class F>
inline __attribute__((always_inline)) void forRows(const stencil<3>& st, F&& f)
{
    const int ox = int(st.base[0] & 3), oy = int(st.base[1] & 3);
    for (int a = 0; a < 4; ++a)
    {
        const int ta = ((ox + a) >> 2)*2, na = ((ox + a) & 3)*tileEdge;
        for (int b = 0; b < 4; ++b)
            f((ta + ((oy + b) >> 2))*2, (na + ((oy + b) & 3))*tileEdge, st.w[0][a]*st.w[1][b]);
    }
}

template <class F>
inline __attribute__((always_inline)) void forRows(const stencil<2>& st, F&& f)
{
    const int ox = int(st.base[0] & 3);
    for (int a = 0; a < 4; ++a) f(((ox + a) >> 2)*2, ((ox + a) & 3)*tileEdge, st.w[0][a]);
}

/// f(oz) with oz an std::integral_constant: the stencil's first node within
/// its tile along the last direction (the kernels are compiled per offset)
template <int D, class F>
inline __attribute__((always_inline)) void withOffset(const stencil<D>& st, F&& f)
{
    switch (st.base[D - 1] & 3)
    {
        case 0: f(std::integral_constant<int, 0>()); break;
        case 1: f(std::integral_constant<int, 1>()); break;
        case 2: f(std::integral_constant<int, 2>()); break;
        default: f(std::integral_constant<int, 3>());
    }
}

/// Visits the stencil's nodes in existing tiles: f(tileId, nodeInTile, weight)
/// (for the plan; the per-fit kernels below work on whole tile rows)
template <int D, class F>
void visitStencil(const stencilTiles<D>& tid, const stencil<D>& st, F&& f)
{
    const int oz = int(st.base[D - 1] & 3);
    forRows(st, [&](int t, int n, double w) {
        for (int c = 0; c < 4; ++c)
        {
            const std::int32_t id = tid[t + ((oz + c) >> 2)];
            if (id >= 0) f(std::int64_t(id), n + ((oz + c) & 3), w*st.w[D - 1][c]);
        }
    });
}

/// Per entry t of a stencil's tiles (stencilTiles), the nodes there where the
/// weight w, formed as visitStencil forms it, has w*w > 0 (bit n: node n)
template <int D>
inline std::array<std::uint64_t, (1 << D)> positiveNodes(const stencil<D>& st)
{
    std::array<std::uint64_t, (1 << D)> m{};
    const int oz = int(st.base[D - 1] & 3);
    const double* wz = st.w[D - 1];
    forRows(st, [&](int t, int n, double w) {
        // the row's 4 nodes (bit c: node c along the last direction), from
        // node oz of tile t's row on, then from node 0 of tile t + 1's
        const double w0 = w*wz[0], w1 = w*wz[1], w2 = w*wz[2], w3 = w*wz[3];
        const std::uint64_t p = std::uint64_t(w0*w0 > 0) | std::uint64_t(w1*w1 > 0) << 1
            | std::uint64_t(w2*w2 > 0) << 2 | std::uint64_t(w3*w3 > 0) << 3;
        m[t] |= ((p << oz) & 15) << n;
        if (oz > 0) m[t + 1] |= (p >> (4 - oz)) << n;
    });
    return m;
}

/// Row n (a node of the tile where a tile row starts) of tile id, NC values
/// a node; absent where id < 0: then the given stand-in (zeros to read, a
/// sink to write)
template <int D, int NC, class T>
inline __attribute__((always_inline)) T* tileRow(T* phi, std::int32_t id, int n, T* absent)
{
    return id >= 0 ? phi + (std::int64_t(id)*tileLayout<D>::nodesPerTile + n)*NC : absent;
}

/// u[(first + c)*NC + k] = w[c] r[k] for the 4 nodes c along the last
/// direction: a stencil row's values from a point's (NC values) and its
/// last-direction weights w, from node first of u on
template <int NC>
inline __attribute__((always_inline)) void lastDirection(const double* w, const double* r, int first, double* u)
{
    for (int c = 0; c < 4; ++c)
        for (int k = 0; k < NC; ++k) u[(first + c)*NC + k] = w[c]*r[k];
}

/// A stencil row whose last-direction nodes start at node OZ of a tile row
/// (NC values a node, the tile row at p0) and go on at node 0 of the next
/// tile's row (p1, used when OZ > 0): the 4 nodes' values in stencil order
template <int NC, int OZ>
inline __attribute__((always_inline)) vrow<4*NC> loadSplit(const double* p0, const double* p1)
{
    constexpr int L = (4 - OZ)*NC;  // values from p0 (from p0[OZ*NC])
    vrow<4*NC> r;
    for (int i = 0; i < 2*NC; ++i)
    {
        const int j = 2*i;
        if (j + 1 < L) r.v[i] = *reinterpret_cast<const v2du*>(p0 + OZ*NC + j);
        else if (j >= L) r.v[i] = *reinterpret_cast<const v2du*>(p1 + (j - L));
        else r.v[i] = v2d{p0[OZ*NC + j], p1[0]};
    }
    return r;
}

/// The same split row += w*a
template <int NC, int OZ>
inline __attribute__((always_inline)) void addSplit(double* p0, double* p1, double w, const vrow<4*NC>& a)
{
    constexpr int L = (4 - OZ)*NC;
    for (int i = 0; i < 2*NC; ++i)
    {
        const int j = 2*i;
        const v2d x = w*a.v[i];
        if (j + 1 < L) *reinterpret_cast<v2du*>(p0 + OZ*NC + j) += x;
        else if (j >= L) *reinterpret_cast<v2du*>(p1 + (j - L)) += x;
        else { p0[OZ*NC + j] += x[0]; p1[0] += x[1]; }
    }
}

/// How a scatter writes: adds, stores, or stores the selected components only
enum class put { add, store, select };

/// The same split row = w*a (select: only in the components whose flag in
/// on[0..NC) is set)
template <int NC, int OZ, put P>
inline __attribute__((always_inline)) void storeSplit(double* p0, double* p1, double w, const vrow<4*NC>& a,
                                                      const bool* on)
{
    constexpr int L = (4 - OZ)*NC;
    for (int i = 0; i < 2*NC; ++i)
    {
        const int j = 2*i;
        const v2d x = w*a.v[i];
        double* lo = j >= L ? p1 + (j - L) : p0 + OZ*NC + j;
        double* hi = j + 1 < L || j >= L ? lo + 1 : p1;
        if (P == put::store || on[j % NC]) *lo = x[0];
        if (P == put::store || on[(j + 1) % NC]) *hi = x[1];
    }
}

/// The value at a stencil (NC values per node), the stencil's first node at
/// OZ along the last direction within its tile: its rows are summed with the
/// other directions' weights (each row read as one vector: its tile row from
/// OZ on, then the next tile's row), then weighted along the last direction.
/// Absent tiles read as zero.
template <int D, int NC, int OZ>
void sweepStencil(const double* phi, const stencilTiles<D>& tid, const stencil<D>& st, double* out)
{
    constexpr int R = 4*NC;
    static constexpr double zero[R] = {};
    auto row = [phi, &tid](int t, int n) { return tileRow<D, NC>(phi, tid[t], n, zero); };
    vrow<R> acc = {};
    forRows(st, [&](int t, int n, double w) {
        axpy<R>(acc, w, loadSplit<NC, OZ>(row(t, n), OZ ? row(t + 1, n) : zero));
    });
    addRowSum<NC>(acc, st.w[D - 1], out);
}

#ifdef MBA_WIDE_VECTORS
/// sweepStencil in vectors of four doubles: each stencil row is read as whole
/// tile rows (4 nodes from node 0, aligned), the one holding its first nodes
/// into accumulator a[0] and, when OZ > 0, the next tile's into a[1] (for OZ
/// = 0 the two take alternate rows: two add chains either way); node c of
/// the stencil row is then node OZ + c of the tile rows a[0] | a[1]
template <int D, int NC, int OZ>
MBA_WIDE_TARGET void sweepStencilWide(const double* phi, const stencilTiles<D>& tid, const stencil<D>& st,
                                      double* out)
{
    constexpr int R = 4*NC;
    static constexpr double zero[R] = {};
    auto row = [phi, &tid](int t, int n) __attribute__((always_inline)) {
        return tileRow<D, NC>(phi, tid[t], n, zero);
    };
    vrow<R, 4> a[2] = {};
    int i = 0;
    forRows(st, [&](int t, int n, double w) __attribute__((always_inline)) {
        if (OZ) axpy<R, 4>(a[1], w, row(t + 1, n));
        axpy<R, 4>(a[OZ ? 0 : i++ & 1], w, row(t, n));
    });
    if (!OZ) add(a[0], a[1]);
    double s[2*R];
    a[0].store(s);
    a[1].store(s + R);
    for (int c = 0; c < 4; ++c)
        for (int k = 0; k < NC; ++k) out[k] += st.w[D - 1][c]*s[(OZ + c)*NC + k];
}
#endif

template <int D, int NC>
void sweepStencil(const double* phi, const stencilTiles<D>& tid, const stencil<D>& st, double* out)
{
#ifdef MBA_WIDE_VECTORS
    if (wideVectors())
    {
        withOffset(st, [&](auto oz) { sweepStencilWide<D, NC, decltype(oz)::value>(phi, tid, st, out); });
        return;
    }
#endif
    withOffset(st, [&](auto oz) { sweepStencil<D, NC, decltype(oz)::value>(phi, tid, st, out); });
}

/// The values at a stencil's nodes (absent tiles read as zero) as a plain
/// block of 4^D nodes, the last direction fastest, NC values a node: row i
/// of the stencil (in forRows' order) at block[i*4*NC]
template <int D, int NC, int OZ>
inline __attribute__((always_inline)) void gatherStencil(const double* phi, const stencilTiles<D>& tid,
                                                         const stencil<D>& st, double* block)
{
    constexpr int R = 4*NC;
    static constexpr double zero[R] = {};
    auto row = [phi, &tid](int t, int n) { return tileRow<D, NC>(phi, tid[t], n, zero); };
    int i = 0;
    forRows(st, [&](int t, int n, double) {
        loadSplit<NC, OZ>(row(t, n), OZ ? row(t + 1, n) : zero).store(block + R*i++);
    });
}

template <int D, int NC>
inline __attribute__((always_inline)) void gatherStencil(const double* phi, const stencilTiles<D>& tid,
                                                         const stencil<D>& st, double* block)
{
    withOffset(st, [&](auto oz) { gatherStencil<D, NC, decltype(oz)::value>(phi, tid, st, block); });
}

/// Adds w_n r (NC values) to each node n of the stencil, w_n the product of
/// the stencil's weights (given cubed, for the fit's delta), row by row as the
/// sweep reads them (or stores it: put). Nodes in absent tiles (id < 0) are
/// left out.
template <int D, int NC, int OZ, put P>
void scatterStencil(double* delta, const stencilTiles<D>& tid, const stencil<D>& st, const double* r,
                    const bool* on)
{
    constexpr int R = 4*NC;
    double u[R], sink[R] = {};
    lastDirection<NC>(st.w[D - 1], r, 0, u);
    const vrow<R> v = vrow<R>::load(u);
    auto row = [delta, &tid, &sink](int t, int n) { return tileRow<D, NC>(delta, tid[t], n, sink); };
    forRows(st, [&](int t, int n, double w) {
        if (P == put::add) addSplit<NC, OZ>(row(t, n), OZ ? row(t + 1, n) : sink, w, v);
        else storeSplit<NC, OZ, P>(row(t, n), OZ ? row(t + 1, n) : sink, w, v, on);
    });
}

#ifdef MBA_WIDE_VECTORS
/// scatterStencil's add in vectors of four doubles: whole tile rows (as in
/// sweepStencilWide) += w u, u holding w_c r at node OZ + c of the tile rows
/// and 0 at their other nodes. The rows of absent tiles go to a sink, zeroed
/// first: it is read and added to like a row (unwritten memory may hold a
/// signalling NaN, a trapped floating-point exception under FOAM_SIGFPE)
template <int D, int NC, int OZ>
MBA_WIDE_TARGET void scatterStencilWide(double* delta, const stencilTiles<D>& tid, const stencil<D>& st,
                                        const double* r)
{
    constexpr int R = 4*NC;
    double u[2*R] = {}, sink[R] = {};
    lastDirection<NC>(st.w[D - 1], r, OZ, u);
    const vrow<R, 4> ua = vrow<R, 4>::load(u), ub = vrow<R, 4>::load(u + R);
    auto addRow = [delta, &tid, &sink](int t, int n, double w, const vrow<R, 4>& v) __attribute__((always_inline)) {
        double* p = tileRow<D, NC>(delta, tid[t], n, sink);
        vrow<R, 4> x = vrow<R, 4>::load(p);
        axpy<R, 4>(x, w, v);
        x.store(p);
    };
    forRows(st, [&](int t, int n, double w) __attribute__((always_inline)) {
        addRow(t, n, w, ua);
        if (OZ) addRow(t + 1, n, w, ub);
    });
}

/// scatterStencilWide for a run of n points whose stencils share their nodes
/// (the same first node: coarse levels, where many points lie in one cell):
/// the run is summed into a plain 4^D block of the stencil's nodes (whole
/// rows of 4 nodes whatever the offset in the tiles), per chunk of points
/// each row's sum over the chunk formed in registers, and the block is added
/// to the lattice once (st: the points' stencils, r: their values, NC a point)
template <int D, int NC, int OZ>
MBA_WIDE_TARGET void scatterRunWide(double* delta, const stencilTiles<D>& tid, const stencil<D>* st,
                                    const double* r, std::size_t n)
{
    constexpr int R = 4*NC;
    constexpr int nRows = D == 3 ? 16 : 4;
    constexpr std::size_t chunk = 16;
    vrow<R, 4> block[nRows] = {};
    vrow<R, 4> u[chunk];            // per point: its values times the last direction's weights
    double w[chunk][nRows];         // per point: its rows' weights in the other directions
    for (std::size_t p0 = 0; p0 < n; p0 += chunk)
    {
        const std::size_t m = std::min(chunk, n - p0);
        for (std::size_t j = 0; j < m; ++j)
        {
            const stencil<D>& sj = st[p0 + j];
            double uj[R];
            lastDirection<NC>(sj.w[D - 1], r + (p0 + j)*NC, 0, uj);
            u[j] = vrow<R, 4>::load(uj);
            int i = 0;
            forRows(sj, [&](int, int, double wr) { w[j][i++] = wr; });
        }
        // two rows at a time: independent add chains
        for (int i = 0; i < nRows; i += 2)
        {
            vrow<R, 4> acc[2] = {};
            for (std::size_t j = 0; j < m; ++j)
            {
                axpy<R, 4>(acc[0], w[j][i], u[j]);
                axpy<R, 4>(acc[1], w[j][i + 1], u[j]);
            }
            add(block[i], acc[0]);
            add(block[i + 1], acc[1]);
        }
    }
    double sink[R] = {};
    int i = 0;
    forRows(st[0], [&](int t, int nn, double) {
        double b[R];
        block[i++].store(b);
        addSplit<NC, OZ>(tileRow<D, NC>(delta, tid[t], nn, sink), OZ ? tileRow<D, NC>(delta, tid[t + 1], nn, sink) : sink,
                         1.0, vrow<R>::load(b));
    });
}
#endif

template <int D, int NC, put P = put::add>
void scatterStencil(double* delta, const stencilTiles<D>& tid, const stencil<D>& st, const double* r,
                    const bool* on = nullptr);

/// A run of n points whose stencils share their nodes (the same first node),
/// scattered (put::add) point after point, or as scatterRunWide does
template <int D, int NC>
void scatterRun(double* delta, const stencilTiles<D>& tid, const stencil<D>* st, const double* r, std::size_t n)
{
#ifdef MBA_WIDE_VECTORS
    if (wideVectors())
    {
        withOffset(st[0], [&](auto oz) { scatterRunWide<D, NC, decltype(oz)::value>(delta, tid, st, r, n); });
        return;
    }
#endif
    for (std::size_t j = 0; j < n; ++j) scatterStencil<D, NC>(delta, tid, st[j], r + j*NC);
}

template <int D, int NC, put P>
void scatterStencil(double* delta, const stencilTiles<D>& tid, const stencil<D>& st, const double* r,
                    const bool* on)
{
#ifdef MBA_WIDE_VECTORS
    if (P == put::add && wideVectors())
    {
        withOffset(st, [&](auto oz) { scatterStencilWide<D, NC, decltype(oz)::value>(delta, tid, st, r); });
        return;
    }
#endif
    withOffset(st, [&](auto oz) { scatterStencil<D, NC, decltype(oz)::value, P>(delta, tid, st, r, on); });
}
} // namespace detail

/// Adds the lattice's value at a stencil whose tiles were looked up (nc
/// components per node) to out[0..nc)
template <int D>
void evalStencil(const double* phi, int nc, const stencilTiles<D>& tid, const stencil<D>& st, double* out)
{
    switch (nc)
    {
        case 1: detail::sweepStencil<D, 1>(phi, tid, st, out); break;
        case 2: detail::sweepStencil<D, 2>(phi, tid, st, out); break;
        default: detail::sweepStencil<D, 3>(phi, tid, st, out);
    }
}

} // namespace mba
#endif
