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

namespace detail {
// Per direction: which of the (up to 2) touched tiles holds stencil node a, and where
struct split1
{
    std::int64_t t0;
    int nt, ta[4], oa[4];
    explicit split1(std::int64_t base)
    {
        t0 = base/tileEdge;
        for (int a = 0; a < 4; ++a)
        {
            const std::int64_t n = base + a;
            ta[a] = int(n/tileEdge - t0);
            oa[a] = int(n - (n/tileEdge)*tileEdge);
        }
        nt = ta[3] + 1;
        r[0] = 0;
        for (int a = 1; a < 4; ++a) if (ta[a] != ta[a - 1]) r[ta[a]] = a;
        r[nt] = 4;
    }
    int r[4];   ///< stencil positions [r[i], r[i+1]) lie in tile t0 + i
};

template <int NC>
bool evalStencil(const tileLayout<3>& L, const double* phi, const stencil<3>& st, double* out)
{
    constexpr int npt = tileLayout<3>::nodesPerTile;
    const split1 x(st.base[0]), y(st.base[1]), z(st.base[2]);
    // The (up to 8) tiles first, then one regular 4 x 4 x 4 sweep
    std::int64_t tid[8];
    bool any = false;
    for (int i = 0; i < x.nt; ++i)
        for (int j = 0; j < y.nt; ++j)
            for (int k = 0; k < z.nt; ++k)
            {
                const std::int64_t id = L.find(index<3>{{x.t0 + i, y.t0 + j, z.t0 + k}});
                tid[(i*2 + j)*2 + k] = id;
                any = any || id >= 0;
            }
    if (!any) return false;
    double acc[NC] = {};
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
                const std::int64_t id = tid[iab + z.ta[c]];
                if (id < 0) continue;
                const double w = wab*st.w[2][c];
                const double* p = phi + (id*npt + oab + z.oa[c])*NC;
                for (int v = 0; v < NC; ++v) acc[v] += w*p[v];
            }
        }
    }
    for (int v = 0; v < NC; ++v) out[v] += acc[v];
    return true;
}

template <int NC>
bool evalStencil(const tileLayout<2>& L, const double* phi, const stencil<2>& st, double* out)
{
    constexpr int npt = tileLayout<2>::nodesPerTile;
    const split1 x(st.base[0]), y(st.base[1]);
    double acc[NC] = {};
    bool any = false;
    for (int i = 0; i < x.nt; ++i)
        for (int j = 0; j < y.nt; ++j)
        {
            const std::int64_t id = L.find(index<2>{{x.t0 + i, y.t0 + j}});
            if (id < 0) continue;
            any = true;
            const double* T = phi + id*npt*NC;
            for (int a = x.r[i]; a < x.r[i + 1]; ++a)
            {
                const double* row = T + x.oa[a]*tileEdge*NC;
                for (int b = y.r[j]; b < y.r[j + 1]; ++b)
                {
                    const double w = st.w[0][a]*st.w[1][b];
                    const double* p = row + y.oa[b]*NC;
                    for (int v = 0; v < NC; ++v) acc[v] += w*p[v];
                }
            }
        }
    for (int v = 0; v < NC; ++v) out[v] += acc[v];
    return any;
}
} // namespace detail

/// Adds the lattice's value at a stencil (nc components per node) to out[0..nc).
/// Returns whether any of the stencil's tiles exists.
template <int D>
bool evalStencil(const tileLayout<D>& L, const double* phi, int nc, const stencil<D>& st, double* out)
{
    switch (nc)
    {
        case 1: return detail::evalStencil<1>(L, phi, st, out);
        case 2: return detail::evalStencil<2>(L, phi, st, out);
        default: return detail::evalStencil<3>(L, phi, st, out);
    }
}

/// Create the tiles a stencil touches
template <int D>
void insertStencil(tileLayout<D>& L, const stencil<D>& st)
{
    const indexBox<D> b = st.tiles();
    index<D> t = b.lo;
    for (;;)
    {
        L.findOrInsert(t);
        int d = D - 1;
        while (d >= 0 && t[d] == b.hi[d]) { t[d] = b.lo[d]; --d; }
        if (d < 0) break;
        ++t[d];
    }
}

/// Visit the stencil nodes that exist in the layout: f(tileId, nodeInTile, weight).
/// Returns whether any tile existed.
template <class F>
bool forStencil(const tileLayout<3>& L, const stencil<3>& st, F&& f)
{
    const detail::split1 x(st.base[0]), y(st.base[1]), z(st.base[2]);
    std::int64_t tid[3][3][3];
    bool any = false;
    for (int i = 0; i < x.nt; ++i)
        for (int j = 0; j < y.nt; ++j)
            for (int k = 0; k < z.nt; ++k)
            {
                const index<3> t{{x.t0 + i, y.t0 + j, z.t0 + k}};
                const std::int64_t id = L.find(t);
                tid[i][j][k] = id;
                any = any || id >= 0;
            }
    if (!any) return false;
    for (int a = 0; a < 4; ++a)
    {
        const double wa = st.w[0][a];
        for (int b = 0; b < 4; ++b)
        {
            const double wab = wa*st.w[1][b];
            const int nab = (x.oa[a]*tileEdge + y.oa[b])*tileEdge;
            for (int c = 0; c < 4; ++c)
            {
                const std::int64_t id = tid[x.ta[a]][y.ta[b]][z.ta[c]];
                if (id >= 0) f(id, nab + z.oa[c], wab*st.w[2][c]);
            }
        }
    }
    return true;
}

template <class F>
bool forStencil(const tileLayout<2>& L, const stencil<2>& st, F&& f)
{
    const detail::split1 x(st.base[0]), y(st.base[1]);
    std::int64_t tid[3][3];
    bool any = false;
    for (int i = 0; i < x.nt; ++i)
        for (int j = 0; j < y.nt; ++j)
        {
            const index<2> t{{x.t0 + i, y.t0 + j}};
            const std::int64_t id = L.find(t);
            tid[i][j] = id;
            any = any || id >= 0;
        }
    if (!any) return false;
    for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b)
        {
            const std::int64_t id = tid[x.ta[a]][y.ta[b]];
            if (id >= 0) f(id, x.oa[a]*tileEdge + y.oa[b], st.w[0][a]*st.w[1][b]);
        }
    return true;
}

} // namespace mba
#endif
