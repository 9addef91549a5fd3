// bsplineMorph: OpenFOAM-free multilevel B-spline core
// Tiled control lattices, a point's 4^D stencil and the tiles it touches
// (the kernels that read and write a stencil's nodes: stencilKernels.hpp).
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
#include <cstdint>
#include <vector>

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

    /// The same stencil with its weights cubed (the fit's scatter)
    stencil cubedWeights() const
    {
        stencil s = *this;
        for (int d = 0; d < D; ++d)
            for (double& x : s.w[d]) x = x*x*x;
        return s;
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

    /// The nodes of tile t that the stencil covers (positive: only those of
    /// positive weight), as bits: bit n for node n of the tile, the last
    /// direction fastest
    std::uint64_t nodesIn(const index<D>& t, bool positive = false) const
    {
        // per direction the covered nodes of a row of the tile, spread out
        // to the direction's stride and multiplied in (the rows' bits never
        // overlap: the products carry nothing)
        std::uint64_t bits = 1;
        int stride = 1;
        for (int d = D - 1; d >= 0; --d)
        {
            std::uint64_t spread = 0;
            for (int j = 0; j < tileEdge; ++j)
            {
                const std::int64_t i = t[d]*tileEdge + j - base[d];
                if (i >= 0 && i < 4 && (!positive || w[d][i] > 0)) spread |= std::uint64_t(1) << (j*stride);
            }
            bits *= spread;
            stride *= tileEdge;
        }
        return bits;
    }
};

/// The nodes in a tile's node bits (stencil::nodesIn)
inline int nodeCount(std::uint64_t nodes)
{
    return __builtin_popcountll(nodes);
}

/// The nodes in a list of tiles' node bits
inline std::int64_t nodeCount(const std::vector<std::uint64_t>& tiles)
{
    std::int64_t n = 0;
    for (const std::uint64_t nodes : tiles) n += nodeCount(nodes);
    return n;
}

/// The nodes of tile id set in any of its per values' masks (masks: per a
/// tile, bit n: node n)
inline std::uint64_t anyValue(const std::vector<std::uint64_t>& masks, std::int64_t id, int per)
{
    std::uint64_t nodes = 0;
    for (int c = 0; c < per; ++c) nodes |= masks[std::size_t(id*per + c)];
    return nodes;
}

/// f(n) for each node n in a tile's node bits, in ascending order
template <class F>
void forEachNode(std::uint64_t nodes, F f)
{
    for (; nodes; nodes &= nodes - 1) f(__builtin_ctzll(nodes));
}

/// Tile c of a stencil's tiles (box: stencil::tiles()): entry c of
/// stencilTiles; may lie beyond the box (no such tile) along a direction
/// where the stencil has one tile
template <int D>
inline index<D> stencilTile(const indexBox<D>& box, int c)
{
    index<D> t;
    for (int d = 0; d < D; ++d) t[d] = box.lo[d] + ((c >> (D - 1 - d)) & 1);
    return t;
}

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
        const index<D> t = stencilTile<D>(b, c);
        bool in = true;
        for (int d = 0; d < D; ++d) in = in && t[d] <= b.hi[d];
        const std::int64_t id = in ? L.find(t) : -1;
        tid[c] = std::int32_t(id);
        any = any || id >= 0;
    }
    return any;
}

/// Create the tiles a stencil touches
template <int D>
void insertStencil(tileLayout<D>& L, const stencil<D>& st)
{
    forEachIndex<D>(st.tiles(), [&](const index<D>& t) { L.findOrInsert(t); });
}

/// Level-0 local coordinates u at the level of scale s = 2^k: u*s (exact)
template <int D>
inline point<D> scaled(point<D> u, double s)
{
    for (auto& x : u) x *= s;
    return u;
}

/// The stencil at the level of scale s = 2^k of the point with level-0 local
/// coordinates u0
template <int D>
inline __attribute__((always_inline)) stencil<D> levelStencil(const point<D>& u0, double s)
{
    return stencil<D>(scaled<D>(u0, s).data());
}

} // namespace mba
#endif
