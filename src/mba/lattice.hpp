// bsplineMorph: OpenFOAM-free multilevel B-spline core
// Tiled control lattices and the 4^D stencil kernels.
//
// A level's nodes are grouped in tiles of tileEdge^D nodes. A layout maps tile
// coordinates to tile ids, either densely (every tile exists, id = linear
// index: for coarse levels) or sparsely (only touched tiles, in a hash map: no
// global array at fine levels). Node values live in a separate array indexed
// (tileId*nodesPerTile + nodeInTile)*nValues + value.
#ifndef MBA_LATTICE_HPP
#define MBA_LATTICE_HPP

#include "basis.hpp"
#include "geometry.hpp"
#include "hashMap.hpp"

#include <cmath>

namespace mba {

constexpr int tileEdge = 4;

template <int D> struct tileSize;
template <> struct tileSize<2> { static constexpr int nodes = tileEdge*tileEdge; };
static_assert(tileEdge == 4, "the kernels take a stencil row as at most two tile rows of 4 nodes");
template <> struct tileSize<3> { static constexpr int nodes = tileEdge*tileEdge*tileEdge; };

template <int D>
class tileLayout
{
    bool dense_ = false;
    index<D> ntile_{};          ///< tiles per direction
    hashMap map_;               ///< sparse: linear tile index -> tile id
    std::vector<std::uint64_t> keys_; ///< sparse: tile id -> linear tile index

public:
    static constexpr int nodesPerTile = tileSize<D>::nodes;

    /// A layout for a lattice of nodes[d] nodes per direction
    void init(const index<D>& nodes, bool dense)
    {
        dense_ = dense;
        double total = 1;
        for (int d = 0; d < D; ++d)
        {
            ntile_[d] = (nodes[d] + tileEdge - 1)/tileEdge;
            total *= double(ntile_[d]);
        }
        precondition(total < 4e18, "mba: lattice too fine for 64-bit tile keys (reduce maxLevels or initialGrid)");
        map_ = hashMap();
        keys_.clear();
    }

    bool dense() const { return dense_; }

    std::int64_t size() const
    {
        if (!dense_) return std::int64_t(keys_.size());
        std::int64_t n = 1;
        for (int d = 0; d < D; ++d) n *= ntile_[d];
        return n;
    }

    std::uint64_t key(const index<D>& t) const
    {
        std::uint64_t k = 0;
        for (int d = 0; d < D; ++d) k = k*std::uint64_t(ntile_[d]) + std::uint64_t(t[d]);
        return k;
    }

    index<D> coord(std::uint64_t k) const
    {
        index<D> t;
        for (int d = D - 1; d >= 0; --d)
        {
            t[d] = std::int64_t(k % std::uint64_t(ntile_[d]));
            k /= std::uint64_t(ntile_[d]);
        }
        return t;
    }

    /// Linear tile index of tile id
    std::uint64_t keyOf(std::int64_t id) const { return dense_ ? std::uint64_t(id) : keys_[id]; }

    /// Tile id, or -1 when absent
    std::int64_t find(const index<D>& t) const
    {
        return dense_ ? std::int64_t(key(t)) : map_.find(key(t));
    }

    std::int64_t findKey(std::uint64_t k) const
    {
        return dense_ ? std::int64_t(k) : map_.find(k);
    }

    /// Tile id, inserting the tile when absent
    std::int64_t findOrInsertKey(std::uint64_t k)
    {
        if (dense_) return std::int64_t(k);
        const std::int32_t id = map_.insert(k, std::int32_t(keys_.size()));
        if (id == std::int32_t(keys_.size())) keys_.push_back(k);
        return id;
    }

    std::int64_t findOrInsert(const index<D>& t) { return findOrInsertKey(key(t)); }

    std::size_t bytes() const
    {
        return dense_ ? 0 : map_.bytes() + keys_.capacity()*sizeof(std::uint64_t);
    }
};

/// The 4^D stencil of a point at one level: first node per direction and weights
template <int D> struct stencil
{
    index<D> base;
    double w[D][4];

    stencil() = default;

    /// From level-local coordinates u >= 0 (as domain::local0 makes them):
    /// cell floor(u), s = u - floor(u); floor as truncation, which is one
    /// instruction on every x86-64 (std::floor is a call without SSE4.1)
    explicit stencil(const double* u)
    {
        for (int d = 0; d < D; ++d)
        {
            base[d] = std::int64_t(u[d]);
            cubicBasis(u[d] - double(base[d]), w[d]);
        }
    }

    double sumSquares() const
    {
        double s = 1;
        for (int d = 0; d < D; ++d)
            s *= w[d][0]*w[d][0] + w[d][1]*w[d][1] + w[d][2]*w[d][2] + w[d][3]*w[d][3];
        return s;
    }

    /// Inclusive box of the tiles the stencil touches
    indexBox<D> tiles() const
    {
        indexBox<D> b;
        for (int d = 0; d < D; ++d)
        {
            b.lo[d] = base[d]/tileEdge;
            b.hi[d] = (base[d] + 3)/tileEdge;
        }
        return b;
    }
};

/// Ids of the (up to 2^D) tiles a stencil touches, -1 where absent: entry
/// (i*2 + j)*2 + k holds tile (t0 + i, t0 + j, t0 + k), t0 = the stencil's first tile
template <int D> using stencilTiles = std::array<std::int32_t, 1 << D>;

/// Looks up the tiles of a stencil; returns whether any exists
template <int D>
bool findTiles(const tileLayout<D>& L, const stencil<D>& st, stencilTiles<D>& tid)
{
    const indexBox<D> b = st.tiles();
    bool any = false;
    for (int c = 0; c < (1 << D); ++c)
    {
        index<D> t;
        bool in = true;
        for (int d = 0; d < D; ++d)
        {
            t[d] = b.lo[d] + ((c >> (D - 1 - d)) & 1);
            in = in && t[d] <= b.hi[d];
        }
        const std::int64_t id = in ? L.find(t) : -1;
        tid[c] = std::int32_t(id);
        any = any || id >= 0;
    }
    return any;
}

namespace detail {
/// Rows of N doubles as vectors of two (GCC's vector extension: SSE2 on
/// x86-64, NEON on arm64), kept in registers; per lane the same arithmetic as
/// scalar code
typedef double v2d __attribute__((vector_size(16)));
typedef double v2du __attribute__((vector_size(16), aligned(8), may_alias)); ///< unaligned, in arrays of double
template <int N> struct vrow
{
    static_assert(N % 2 == 0, "rows of 4 nodes");
    v2d v[N/2];

    /// The row p[0..N)
    static inline __attribute__((always_inline)) vrow load(const double* p)
    {
        vrow r;
        const v2du* q = reinterpret_cast<const v2du*>(p);
        for (int i = 0; i < N/2; ++i) r.v[i] = q[i];
        return r;
    }

    /// Stores the row to p[0..N)
    void store(double* p) const
    {
        v2du* q = reinterpret_cast<v2du*>(p);
        for (int i = 0; i < N/2; ++i) q[i] = v[i];
    }
};

/// a += w*b
template <int N>
inline __attribute__((always_inline)) void axpy(vrow<N>& a, double w, const vrow<N>& b)
{
    for (int i = 0; i < N/2; ++i) a.v[i] += w*b.v[i];
}

/// a += w*p (p a row in memory)
template <int N>
inline __attribute__((always_inline)) void axpy(vrow<N>& a, double w, const double* p)
{
    axpy<N>(a, w, vrow<N>::load(p));
}

/// Adds to out[0..NC) the row sum r (4 nodes of NC values along the last
/// direction) weighted by the stencil's last-direction weights w
template <int NC>
inline __attribute__((always_inline)) void addRowSum(const vrow<4*NC>& r, const double* w, double* out)
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
    constexpr int npt = tileLayout<D>::nodesPerTile, R = 4*NC;
    static constexpr double zero[R] = {};
    auto row = [phi, &tid](int t, int n) {
        const std::int32_t id = tid[t];
        return id >= 0 ? phi + (std::int64_t(id)*npt + n)*NC : zero;
    };
    vrow<R> acc = {};
    forRows(st, [&](int t, int n, double w) {
        axpy<R>(acc, w, loadSplit<NC, OZ>(row(t, n), OZ ? row(t + 1, n) : zero));
    });
    addRowSum<NC>(acc, st.w[D - 1], out);
}

template <int D, int NC>
void sweepStencil(const double* phi, const stencilTiles<D>& tid, const stencil<D>& st, double* out)
{
    switch (st.base[D - 1] & 3)
    {
        case 0: sweepStencil<D, NC, 0>(phi, tid, st, out); break;
        case 1: sweepStencil<D, NC, 1>(phi, tid, st, out); break;
        case 2: sweepStencil<D, NC, 2>(phi, tid, st, out); break;
        default: sweepStencil<D, NC, 3>(phi, tid, st, out);
    }
}

/// Adds w_n r (NC values) to each node n of the stencil, w_n the product of
/// the stencil's weights (given cubed, for the fit's delta), row by row as the
/// sweep reads them (or stores it: put). Nodes in absent tiles (id < 0) are
/// left out.
template <int D, int NC, int OZ, put P>
void scatterStencil(double* delta, const stencilTiles<D>& tid, const stencil<D>& st, const double* r,
                    const bool* on)
{
    constexpr int npt = tileLayout<D>::nodesPerTile, R = 4*NC;
    double u[R], sink[R] = {};
    for (int c = 0; c < 4; ++c)
        for (int k = 0; k < NC; ++k) u[c*NC + k] = st.w[D - 1][c]*r[k];
    const vrow<R> v = vrow<R>::load(u);
    auto row = [delta, &tid, &sink](int t, int n) {
        const std::int32_t id = tid[t];
        return id >= 0 ? delta + (std::int64_t(id)*npt + n)*NC : sink;
    };
    forRows(st, [&](int t, int n, double w) {
        if (P == put::add) addSplit<NC, OZ>(row(t, n), OZ ? row(t + 1, n) : sink, w, v);
        else storeSplit<NC, OZ, P>(row(t, n), OZ ? row(t + 1, n) : sink, w, v, on);
    });
}

template <int D, int NC, put P = put::add>
void scatterStencil(double* delta, const stencilTiles<D>& tid, const stencil<D>& st, const double* r,
                    const bool* on = nullptr)
{
    switch (st.base[D - 1] & 3)
    {
        case 0: scatterStencil<D, NC, 0, P>(delta, tid, st, r, on); break;
        case 1: scatterStencil<D, NC, 1, P>(delta, tid, st, r, on); break;
        case 2: scatterStencil<D, NC, 2, P>(delta, tid, st, r, on); break;
        default: scatterStencil<D, NC, 3, P>(delta, tid, st, r, on);
    }
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

/// Adds the lattice's value at a stencil to out[0..nc). Returns whether any of
/// the stencil's tiles exists.
template <int D>
bool evalStencil(const tileLayout<D>& L, const double* phi, int nc, const stencil<D>& st, double* out)
{
    stencilTiles<D> tid;
    if (!findTiles(L, st, tid)) return false;
    evalStencil(phi, nc, tid, st, out);
    return true;
}

/// Create the tiles a stencil touches
template <int D>
void insertStencil(tileLayout<D>& L, const stencil<D>& st)
{
    forEachIndex<D>(st.tiles(), [&](const index<D>& t) { L.findOrInsert(t); });
}

} // namespace mba
#endif
