// The planning of a level (levelPlan.cpp), its steps about the points alone
// at their nodes: the nodes that one and that two or more points reach, the
// separated levels and the lone points, and the tiles of lone points' nodes
// alone numbered last.
#include "levelPlanner.hpp"
#include "stencilKernels.hpp"

#include <algorithm>
#include <type_traits>

namespace mba {

/// levelPlan::coefficientNodes: the nodes where omega, the ranks' partial
/// sums (each >= 0) added, is > 0: where this rank's is (ownMask_) or
/// another rank's is (maskFrom_); and multiNodes_, where two or more
/// points' w^2 are (ownMulti_, or more than one of those sums)
template <int D>
void levelPlanner<D>::findCoefficientNodes()
{
    const int per = omegaPerNode_;
    std::vector<std::uint64_t>& cn = L_.coefficientNodes;
    if (L_.ownIsView)
    {
        cn = ownMask_;
        multiNodes_ = std::move(ownMulti_);
    }
    else
    {
        cn.assign(std::size_t(L_.view.size())*per, 0);
        multiNodes_.assign(cn.size(), 0);
        for (std::int64_t o = 0; o < nOwn_; ++o)
            for (int j = 0; j < per; ++j)
            {
                cn[ownToView_[o]*per + j] |= ownMask_[o*per + j];
                multiNodes_[ownToView_[o]*per + j] |= ownMulti_[o*per + j];
            }
    }
    for (int r = 0; r < nRanks_; ++r)
        for (std::size_t t = 0; t < L_.tilesFrom[r].size(); ++t)
            for (int j = 0; j < per; ++j)
            {
                const std::uint64_t from = maskFrom_[r][t*per + j];
                const std::size_t at = std::size_t(L_.tilesFrom[r][t])*per + j;
                multiNodes_[at] |= cn[at] & from;
                cn[at] |= from;
            }
}

/// Numbers last the view tiles (sparse) that hold lone points' nodes alone,
/// which then hold no phi (levelPlan::storedTiles): the tiles of the points
/// that are not lone, and those that partial sums go to or come from, are
/// kept first, in their order. Plain levels (the others' exchanges write
/// their own tiles whole)
template <int D>
void levelPlanner<D>::storeLoneTilesLast()
{
    const std::int64_t n = L_.view.size();
    std::vector<std::uint8_t> kept(n, 0);
    for (std::size_t q = 0; q < L_.lone.size(); ++q)
        if (!L_.lone[q]) for (const std::int32_t id : L_.controlTiles[q]) if (id >= 0) kept[id] = 1;
    for (int r = 0; r < nRanks_; ++r)
    {
        for (const std::int64_t id : L_.tilesTo[r]) kept[id] = 1;
        for (const std::int64_t id : L_.tilesFrom[r]) kept[id] = 1;
    }
    std::vector<std::int64_t> order(n), to(n);
    for (std::int64_t id = 0; id < n; ++id) order[id] = id;
    std::stable_partition(order.begin(), order.end(), [&](std::int64_t id) { return kept[id] != 0; });
    L_.storedTiles = std::count(kept.begin(), kept.end(), std::uint8_t(1));
    if (L_.storedTiles == n) return;
    tileLayout<D> view;
    view.init(nodes_, false);
    for (std::int64_t t = 0; t < n; ++t) to[order[t]] = view.findOrInsertKey(L_.view.keyOf(order[t]));
    L_.view = std::move(view);
    // the arrays by tile id, in the new order: in place, cycle after cycle
    // (omega is formed after this, on the stored tiles)
    std::vector<std::uint8_t> done(n);
    const auto permute = [&](auto& v, std::size_t per) {
        if (v.empty()) return;
        std::fill(done.begin(), done.end(), 0);
        typename std::decay<decltype(v)>::type held(per);
        for (std::int64_t first = 0; first < n; ++first)
        {
            if (done[first]) continue;
            std::copy_n(&v[first*per], per, held.begin());
            for (std::int64_t id = to[first]; ; id = to[id])
            {
                std::swap_ranges(held.begin(), held.end(), v.begin() + id*per);
                done[id] = 1;
                if (id == first) break;
            }
        }
    };
    permute(L_.coefficientNodes, std::size_t(omegaPerNode_));
    permute(loneNodes_, 1);
    for (stencilTiles<D>& tid : L_.controlTiles)
        for (std::int32_t& id : tid) if (id >= 0) id = std::int32_t(to[id]);
    for (auto* lists : {&L_.tilesTo, &L_.tilesFrom})
        for (auto& tiles : *lists)
            for (std::int64_t& id : tiles) id = to[id];
    for (std::int64_t& id : L_.sharedWithLower) id = to[id];
    for (std::int64_t& id : ownToView_) id = to[id];
}

/// levelPlan::lonePoints and the lone points of each view tile
template <int D>
void levelPlanner<D>::indexLonePoints()
{
    const std::size_t nt = std::size_t(L_.view.size());
    for (std::size_t q = 0; q < L_.lone.size(); ++q)
        if (L_.lone[q]) L_.lonePoints.push_back(std::uint32_t(q));
    std::vector<std::uint32_t>& start = L_.loneTileStart;
    start.assign(nt + 1, 0);
    for (const std::uint32_t q : L_.lonePoints)
        for (const std::int32_t id : L_.controlTiles[q]) if (id >= 0) ++start[id + 1];
    for (std::size_t t = 0; t < nt; ++t) start[t + 1] += start[t];
    L_.loneOnTile.resize(start[nt]);
    std::vector<std::uint32_t> at(start.begin(), start.end() - 1);
    for (std::uint32_t j = 0; j < L_.lonePoints.size(); ++j)
        for (const std::int32_t id : L_.controlTiles[L_.lonePoints[j]]) if (id >= 0) L_.loneOnTile[at[id]++] = j;
    L_.loneResiduals.assign(L_.lonePoints.size()*nc_, 0.0);
}

/// Whether own point q (stencil st) is alone at every node of its stencil:
/// in every component it constrains, omega (the sum over all ranks, not yet
/// inverted) is its own w^2 alone, summed as the plan summed it (0 + w*w:
/// exact), also at nodes where its weight is 0; with freeZero, omega is 0
/// in the components it leaves free. The nodes' masks (coefficientNodes,
/// multiNodes_) decide but where another point's w^2 is > 0 as well: there
/// omega's value does (omegaAt: a weight whose square is below the
/// rounding of the point's own leaves the sum at w^2)
template <int D>
bool levelPlanner<D>::aloneAtNodes(std::size_t q, const stencil<D>& st, bool freeZero) const
{
    const std::size_t i = ctrl_.order[q];
    const int per = omegaPerNode_;
    const auto positive = detail::positiveNodes(st);
    const indexBox<D> tb = st.tiles();
    const stencilTiles<D>& tid = L_.controlTiles[q];
    const auto constrains = [&](int c) { return per == 1 || ctrl_.mask[i*nc_ + c] != 0; };
    bool shared = false;
    for (int t = 0; t < (1 << D); ++t)
    {
        if (tid[t] < 0) continue;
        const std::uint64_t nodes = st.nodesIn(stencilTile<D>(tb, t));
        for (int c = 0; c < per; ++c)
        {
            const std::size_t j = std::size_t(tid[t])*per + c;
            const std::uint64_t others = constrains(c) ? nodes & ~positive[t] : freeZero ? nodes : 0;
            if (L_.coefficientNodes[j] & others) return false;
            shared = shared || (constrains(c) && (multiNodes_[j] & positive[t]));
        }
    }
    if (!shared) return true;
    bool alone = true;
    detail::visitStencil(tid, st, [&](std::int64_t id, int n, double w) {
        const double* o = omegaAt(id) + n*per;
        for (int c = 0; c < per; ++c)
            if (constrains(c) && (multiNodes_[id*per + c] >> n & 1)) alone = alone && o[c] == w*w;
    });
    return alone;
}

/// Separated: every own point of every rank is alone at its nodes in the
/// components it constrains (a coarse level fails at its first points)
template <int D>
void levelPlanner<D>::testSeparation()
{
    bool alone = true;
    for (std::size_t q = 0; q < ctrl_.order.size() && alone; ++q) alone = aloneAtNodes(q, ctrl_.stencilAt(q, L_.scale), false);
    L_.separated = comm_.max(alone ? 0.0 : 1.0) == 0;
}

/// levelPlan::lone, from omega (before it is inverted). Empty when no point
/// is lone
template <int D>
void levelPlanner<D>::findLonePoints()
{
    const std::size_t nq = ctrl_.order.size();
    std::vector<std::uint8_t> read(nRanks_ > 1 ? L_.view.size() : 0, 0);
    for (const auto& tiles : L_.tilesTo)
        for (const std::int64_t id : tiles) read[id] = 1;
    L_.lone.assign(nq, 0);
    loneNodes_.clear();
    // (stencils q - 1, q and q + 1 in turn: a point with a neighbour in
    // order at the same nodes is not alone)
    stencil<D> before, st, after;
    if (nq > 0) st = ctrl_.stencilAt(0, L_.scale);
    for (std::size_t q = 0; q < nq; before = st, st = after, ++q)
    {
        if (q + 1 < nq) after = ctrl_.stencilAt(q + 1, L_.scale);
        if ((q > 0 && before.base == st.base) || (q + 1 < nq && after.base == st.base)) continue;
        bool alone = true;
        for (const std::int32_t id : L_.controlTiles[q]) alone = alone && !(id >= 0 && !read.empty() && read[id]);
        alone = alone && aloneAtNodes(q, st, true);
        L_.lone[q] = alone;
        if (!alone) continue;
        loneNodes_.resize(std::size_t(L_.view.size()), 0);
        detail::visitStencil(L_.controlTiles[q], st, [&](std::int64_t id, int n, double) {
            loneNodes_[id] |= std::uint64_t(1) << n;
        });
    }
    if (loneNodes_.empty()) L_.lone.clear();
}

template void levelPlanner<2>::findCoefficientNodes();
template void levelPlanner<3>::findCoefficientNodes();
template void levelPlanner<2>::storeLoneTilesLast();
template void levelPlanner<3>::storeLoneTilesLast();
template void levelPlanner<2>::indexLonePoints();
template void levelPlanner<3>::indexLonePoints();
template void levelPlanner<2>::testSeparation();
template void levelPlanner<3>::testSeparation();
template void levelPlanner<2>::findLonePoints();
template void levelPlanner<3>::findLonePoints();

} // namespace mba
