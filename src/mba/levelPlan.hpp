// bsplineMorph: OpenFOAM-free multilevel B-spline core (internal header)
// The plan of one level, made the first time a fit needs the level and kept:
// the tiles of this rank's partial sums ("own" tiles), the view (own and
// received tiles) with 1/omega, and the communication pattern of an apply.
//
// Own tiles are clustered into buckets whose index boxes are all-gathered (a
// small directory of who holds what); each rank asks the owners of the
// buckets that meet its query points' stencils for exactly the tiles those
// stencils touch, saying which nodes of each they read, and receives in
// every apply the owners' partial sums at those nodes (where the owner's
// points have weight). Where the owner's control points that reach those
// nodes are fewer, it sends their coordinates once and their residuals per
// apply instead ("ghosts"), and the asking rank forms the owner's partial
// sums itself. The asking rank's other nodes of the tiles then hold part of
// the sum, which no point reads. (The flat lattice refines them too, but a
// refined node that a point's stencil weighs by w > 0 takes only coarse
// nodes whose basis is positive at the point, the subdivision's weights and
// the basis being non-negative: nodes of the point's coarse stencil, which
// hold the whole sum.)
// A level is "separated" when no two control points share a node: every
// node's phi then comes from one point alone.
#ifndef MBA_LEVELPLAN_HPP
#define MBA_LEVELPLAN_HPP

#include "multilevel.hpp"
#include "hugePages.hpp"
#include "lattice.hpp"
#include "pointSets.hpp"
#include "chunkExchange.hpp"

#include <algorithm>
#include <deque>
#include <functional>
#include <utility>

namespace mba {

/// Clusters of this rank's query points (its active control points and its
/// evaluation points): which remote buckets a level needs (parallel only)
template <int D>
struct queryClusters
{
    std::vector<box<D>> boxes;                      ///< bounding box of each cluster
    std::vector<std::vector<const double*>> points; ///< the points of each cluster
};

/// Clusters of this rank's query points, of at least 64 points each (none
/// on one rank)
template <int D>
queryClusters<D> clusterQueryPoints(const communicator& comm, const controlPoints<D>& ctrl, pointsView<D> eval);

template <int D>
struct levelPlan
{
    static constexpr int npt = tileLayout<D>::nodesPerTile;

    int level = 0;                  ///< k: 0 the coarsest
    double scale = 1;               ///< 2^k: level-k local coordinates u_k = u_0*scale
    tileLayout<D> ownLayout;        ///< tiles holding this rank's partial sums (empty when ownIsView)
    tileLayout<D> view;             ///< own and received tiles: where phi and 1/omega are stored
    bool ownIsView = false;         ///< serial, sparse: the own tiles are the view (ownLayout left empty)
    /// The view tiles [0, storedTiles) hold phi; the others hold nodes of
    /// lone points alone (lone), whose coefficients are not stored: a
    /// sparse view numbers those tiles last (levelPlanner::storeLoneTilesLast)
    std::int64_t storedTiles = 0;

    /// The coefficients at the stored tiles' nodes (tile id x node x component);
    /// during an apply first the partial sums delta. Allocated by the first
    /// apply (a level that no evaluation point reads never has them: see
    /// unreadLevel). Mutable: a separated level's apply stores phi only
    /// where it is read every fit, and the const evaluations that read the
    /// whole lattice store the rest, from the last fit
    /// (storeDeferredCoefficients: a cache, not a change)
    mutable hugeVector<double> phi;
    /// 1/omega at the view's nodes (0 where omega is 0), omegaPerNode a node:
    /// kept after the plan on chunked and tree levels only (their divides
    /// read it; plain levels keep runScales, separated ones divide nothing)
    hugeVector<double> invOmega;
    /// Per view tile and omega value (omegaPerNode a tile): the nodes where
    /// that omega is > 0 (bit n: node n of the tile), which the evaluator
    /// asks (which components a point's stencil has coefficients in)
    std::vector<std::uint64_t> coefficientNodes;

    /// No two control points (of any rank) share a node of their stencils
    /// (fine levels, where the points are farther apart than a stencil): a
    /// point's nodes then take phi = w r/sum(w^2) from it alone, and its
    /// residual after the level is r - (r/sum(w^2)) sum(w^2), 0 but for
    /// rounding. Per fit the lattice is neither cleared (but for the tiles
    /// other ranks' sums arrive in) nor scaled by 1/omega nor swept.
    bool separated = false;
    std::vector<std::uint8_t> readEveryFit;    ///< separated: per own point in order, its phi is stored every fit
    std::vector<double> scaledResiduals;       ///< separated: per own point x component, r/sum(w^2) of the last fit
    mutable bool allCoefficientsStored = true; ///< every own point's phi stored since the last fit

    std::vector<std::vector<std::int64_t>> tilesTo;   ///< per rank: own tiles (view ids) whose partial sums it gets
    std::vector<std::vector<std::int64_t>> tilesFrom; ///< per rank: view tiles its partial sums arrive in
    std::vector<std::size_t> receiveCounts;   ///< per rank: values it sends here per apply (direct exchange; 0 when chunked)
    /// Own tiles (view ids) that a lower rank also contributes to: this
    /// rank's partial sums there are set aside and added in rank order
    std::vector<std::int64_t> sharedWithLower;
    std::vector<stencilTiles<D>> controlTiles; ///< the view tiles of the own control points' stencils, in order

    /// Per rank of the direct exchange: whether the partial sums towards
    /// it (To) and from it (From) go as ghosts (the sender's residuals, see
    /// ghostsTo) rather than as tiles. Ghosts may be none: the sender's
    /// points reach no node the reader reads, and nothing travels
    std::vector<std::uint8_t> byGhostsTo, byGhostsFrom;
    /// Per rank, tiles: per tile of tilesTo (tilesFrom) the nodes whose
    /// partial sums travel, bit n for node n: those the reader's stencils
    /// read where the sender's omega is > 0 (elsewhere its sums are 0)
    std::vector<std::vector<std::uint64_t>> nodesTo, nodesFrom;
    std::vector<std::vector<std::uint32_t>> ghostsTo; ///< per rank: own points whose residuals go there (ghost mode)
    /// per rank: its ghosts, D coordinates + nc mask flags + whether it
    /// continues the previous ghost's run of equal stencils (1) each
    std::vector<std::vector<double>> ghostsFrom;
    std::vector<std::vector<stencilTiles<D>>> ghostTiles; ///< per rank: its ghosts' tiles, as positions in tilesFrom
    /// per rank: its ghosts' stencils (weights cubed unless separated) and 1/sum(w^2)
    std::vector<std::vector<stencil<D>>> ghostStencils;
    std::vector<std::vector<double>> ghostScales;

    bool chunked = false;           ///< the partial sums meet in chunks (chunks), not directly
    chunkExchange chunks;

    /// Chunked or tree: the own tiles (view ids), all that an apply clears
    /// (the other tiles' nodes are received whole or never written)
    std::vector<std::int64_t> ownInView;

    /// The partial sums meet in a tree of all ranks (treeSum): the values at
    /// the nodes where omega > 0 of the level's tiles of every rank, in key
    /// order, nodes in order
    bool tree = false;
    std::int64_t treeValues = 0;            ///< tree: values summed
    std::vector<std::int64_t> treeStart;    ///< tree: per view tile, where its values start (-1: none)
    std::vector<std::uint64_t> treeNodes;   ///< tree: per view tile, its nodes among them (bit n: node n)

    /// Plain levels (neither separated nor chunked nor tree): the view's
    /// nodes where omega > 0 in some component, as runs [first, first + n)
    /// of consecutive nodes, or one run of all nodes where those are most;
    /// without the lone points' nodes (lone). phi is 0 at every other node in
    /// every fit (no control point reaches them), so an apply clears and
    /// divides these only.
    std::vector<std::pair<std::int64_t, std::int64_t>> coefficientRuns;
    /// Plain levels: 1/omega at the nodes of coefficientRuns, run after run
    /// (omegaPerNode a node), what the divide reads in sequence
    hugeVector<double> runScales;

    /// Levels not separated: per own point in order, 1 where the point is
    /// "lone": alone at every node of its stencil (omega there is its own w^2
    /// in the components it constrains and 0 in the others: no other point
    /// of any rank reaches those nodes), with no tile that another rank reads
    /// and no neighbour in order with its first node (a run). Its nodes then
    /// take phi = w r/sum(w^2) from it alone, as on a separated level, and
    /// its residual after the level is r - (r/sum(w^2)) sum(w^2). Those
    /// coefficients are not stored (phi is 0 at its nodes): where a stencil
    /// meets its nodes, they add K r/sum(w^2) to the value there, K the
    /// product over the directions of the two stencils' overlapping
    /// weights (forEachLoneOverlap). The same values to round-off, without
    /// the clear, the divide, the sweep and the tiles that hold lone points'
    /// nodes alone. Fine levels, where most points are alone and a few
    /// share nodes (sphereInBox's level 8: 3010 of 4620). Empty: none
    std::vector<std::uint8_t> lone;
    std::vector<std::uint32_t> lonePoints;   ///< the lone points' positions in order, ascending
    /// Per view tile t, the lone points (indices into lonePoints) whose
    /// stencils touch it: loneOnTile[loneTileStart[t] .. loneTileStart[t + 1])
    std::vector<std::uint32_t> loneTileStart, loneOnTile;
    /// Per lone point x component, r/sum(w^2) of the last fit (0 in the
    /// components it leaves free): its coefficients are w times these
    std::vector<double> loneResiduals;

    /// Some evaluation point reads the level (found only for
    /// params::stopUnread; a fit stops before a level that none reads)
    bool read = true;

    levelStats stats;

    /// The layout of the own tiles
    const tileLayout<D>& ownTiles() const { return ownIsView ? view : ownLayout; }

    /// The values phi holds once allocated (nc a node)
    std::size_t coefficientCount(int nc) const { return std::size_t(storedTiles)*npt*nc; }
};

/// f(j, K) for each lone point j of L (lonePoints[j]; ctrl: this rank's
/// control points) whose stencil shares nodes with st, once each, j
/// ascending (tid: st's tiles in L.view, -1 where absent; scratch: a work
/// array). K is the sum over the shared nodes of the product of the two
/// stencils' weights: the point's coefficients add K times its
/// loneResiduals to the value at st. Pairs whose K is 0 are skipped.
template <int D, class F>
void forEachLoneOverlap(const levelPlan<D>& L, const controlPoints<D>& ctrl, const stencil<D>& st,
                        const stencilTiles<D>& tid, std::vector<std::uint32_t>& scratch, F f)
{
    if (L.lonePoints.empty()) return;
    scratch.clear();
    for (const std::int32_t id : tid)
        if (id >= 0) scratch.insert(scratch.end(), L.loneOnTile.begin() + L.loneTileStart[id],
                                    L.loneOnTile.begin() + L.loneTileStart[id + 1]);
    std::sort(scratch.begin(), scratch.end());
    scratch.erase(std::unique(scratch.begin(), scratch.end()), scratch.end());
    for (const std::uint32_t j : scratch)
    {
        const stencil<D> c = ctrl.stencilAt(L.lonePoints[j], L.scale);
        double K = 1;
        for (int d = 0; d < D && K != 0; ++d)
        {
            // node base + a of st is node a - off of c's
            const int off = int(c.base[d] - st.base[d]);
            double s = 0;
            for (int a = std::max(0, off); a <= std::min(3, 3 + off); ++a) s += st.w[d][a]*c.w[d][a - off];
            K *= s;
        }
        if (K != 0) f(j, K);
    }
}

/// What a fit keeps of a level that no evaluation point reads
/// (params::stopUnread): its index, scale and plan statistics, read false
/// (every fit stops before it), no arrays
template <int D>
levelPlan<D> unreadLevel(const levelPlan<D>& L)
{
    levelPlan<D> u;
    u.level = L.level;
    u.scale = L.scale;
    u.read = false;
    u.stats = L.stats;
    u.stats.bytes = 0;
    return u;
}

/// Plans level k. Collective. With isRead, it first asks isRead whether
/// this rank's evaluation points read the level, given the level's tiles
/// (view), level, scale and coefficientNodes alone: the own tiles' nodes
/// where a control point's weight is > 0 (where the plan's omega, a sum of
/// w^2, is), and on several ranks the other ranks' at the nodes of their
/// tiles that this rank's query points' stencils touch, asked as the plan
/// asks them. At the nodes of this rank's evaluation points' stencils the
/// full plan's view has the same coefficient nodes (flatEvaluator::reads
/// gives the same answer), without its omega values (a plan's largest
/// array while it is made), ghosts, exchange and runs. When no rank's
/// isRead is true, the level is returned unplanned (unreadLevel)
template <int D>
levelPlan<D> planLevel(int k, const communicator& comm, const domain<D>& dom, const controlPoints<D>& ctrl,
                       const queryClusters<D>& clusters, int bucketTiles, params::exchangeMode mode,
                       const std::function<bool(const levelPlan<D>&)>& isRead = nullptr);

} // namespace mba
#endif
