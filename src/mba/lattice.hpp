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
static_assert(tileEdge == 2 || tileEdge == 4, "a stencil spans at most 3 tiles per direction");
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

    /// From level-local coordinates u (cell floor(u), s = u - floor(u))
    explicit stencil(const double* u)
    {
        for (int d = 0; d < D; ++d)
        {
            const double f = std::floor(u[d]);
            base[d] = std::int64_t(f);
            cubicBasis(u[d] - f, w[d]);
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
// Per direction: which of the (up to 2) touched tiles holds stencil node a, and where
struct split1
{
    int ta[4], oa[4];
    explicit split1(std::int64_t base)
    {
        const std::int64_t t0 = base/tileEdge;
        for (int a = 0; a < 4; ++a)
        {
            const std::int64_t n = base + a;
            ta[a] = int(n/tileEdge - t0);
            oa[a] = int(n - (n/tileEdge)*tileEdge);
        }
    }
};

/// Visits the stencil's nodes in existing tiles: f(tileId, nodeInTile, weight)
template <class F>
inline __attribute__((always_inline)) void visitStencil(const stencilTiles<3>& tid, const stencil<3>& st, F&& f)
{
    const split1 x(st.base[0]), y(st.base[1]), z(st.base[2]);
    for (int a = 0; a < 4; ++a)
    {
        const int ia = x.ta[a]*2, oa = x.oa[a]*tileEdge;
        const double wa = st.w[0][a];
        for (int b = 0; b < 4; ++b)
        {
            const int iab = (ia + y.ta[b])*2, oab = (oa + y.oa[b])*tileEdge;
            const double wab = wa*st.w[1][b];
            for (int c = 0; c < 4; ++c)
            {
                const std::int32_t id = tid[iab + z.ta[c]];
                if (id >= 0) f(std::int64_t(id), oab + z.oa[c], wab*st.w[2][c]);
            }
        }
    }
}

template <class F>
inline __attribute__((always_inline)) void visitStencil(const stencilTiles<2>& tid, const stencil<2>& st, F&& f)
{
    const split1 x(st.base[0]), y(st.base[1]);
    for (int a = 0; a < 4; ++a)
    {
        const int ia = x.ta[a]*2, oa = x.oa[a]*tileEdge;
        for (int b = 0; b < 4; ++b)
        {
            const std::int32_t id = tid[ia + y.ta[b]];
            if (id >= 0) f(std::int64_t(id), oa + y.oa[b], st.w[0][a]*st.w[1][b]);
        }
    }
}

/// The value at a stencil (NC values per node). visitStencil is inlined here:
/// out of line, the accumulators behind its reference cost 20% of the sweep.
template <int D, int NC>
void sweepStencil(const double* phi, const stencilTiles<D>& tid, const stencil<D>& st, double* out)
{
    constexpr int npt = tileLayout<D>::nodesPerTile;
    double acc[NC] = {};
    visitStencil(tid, st, [phi, &acc](std::int64_t id, int n, double w) {
        const double* p = phi + (id*npt + n)*NC;
        for (int v = 0; v < NC; ++v) acc[v] += w*p[v];
    });
    for (int v = 0; v < NC; ++v) out[v] += acc[v];
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
