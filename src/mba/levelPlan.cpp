// The planning of a level in the steps that levelPlanner::run() takes in
// order (the query clusters and whom a rank asks for which tiles:
// levelPlanRequests.cpp; the choice of the level's exchange:
// levelPlanExchange.cpp).
#include "levelPlanner.hpp"
#include "collectively.hpp"
#include "stencilKernels.hpp"
#include "treeSum.hpp"

#include <algorithm>
#include <cmath>

namespace mba {

/// The level's index, scale and node counts, and its own layout (empty)
template <int D>
void levelPlanner<D>::startLevel(int k)
{
    L_.level = k;
    L_.scale = std::ldexp(1.0, k);
    for (int d = 0; d < D; ++d) nodes_[d] = dom_.nodes(k, d);
    collectively(comm_, [&] { L_.ownLayout.init(nodes_, false); });
}

template <int D>
levelPlan<D> levelPlanner<D>::run(int k, const std::function<bool(const levelPlan<D>&)>& isRead)
{
    startLevel(k);
    ownTiles();
    L_.tilesTo.assign(nRanks_, {});
    asked_.assign(nRanks_, {});
    if (nRanks_ > 1)
    {
        requests_ = tileRequests(bucketDirectory());
        findAskedTiles(comm_.exchange(requests_));
    }
    if (isRead && !readByEvaluation(isRead))
    {
        L_.stats.level = k;
        L_.stats.h = dom_.h0/L_.scale;
        return unreadLevel(L_);
    }
    ownOmega();
    L_.tilesFrom.assign(nRanks_, {});
    keysFrom_.assign(nRanks_, {});
    omegaFrom_.assign(nRanks_, {});
    if (nRanks_ > 1) answerRequests();
    assembleView();
    findControlTiles();
    testSeparation();
    if (!L_.separated) findLonePoints();
    for (double& o : L_.invOmega) o = o > 0 ? 1/o : 0.0;
    findCoefficientNodes();
    findGhostTiles();
    L_.receiveCounts.assign(nRanks_, 0);
    for (int r = 0; r < nRanks_ && nRanks_ > 1; ++r)
        L_.receiveCounts[r] = nc_*(L_.byGhostsFrom[r] ? L_.ghostTiles[r].size()
                                                      : std::size_t(nodeCount(L_.nodesFrom[r])));
    if (nRanks_ > 1) chooseExchange();
    L_.storedTiles = L_.view.size();
    if (!L_.separated && !L_.chunked && !L_.tree)
    {
        if (!L_.lone.empty() && !L_.view.dense()) storeLoneTilesLast();
        findCoefficientRuns();
    }
    if (!L_.lone.empty()) indexLonePoints();
    precondition(L_.view.size() < (std::int64_t(1) << 31), "mba: more than 2^31 tiles in one level");
    if (L_.separated)
    {
        // every point's phi is stored until the evaluator has found the tiles read
        L_.readEveryFit.assign(ctrl_.order.size(), 1);
        L_.scaledResiduals.assign(ctrl_.order.size()*nc_, 0.0);
    }
    keepOmega();
    fillStats();
    return std::move(L_);
}

/// levelPlan::coefficientNodes: the nodes where omega, the ranks' partial
/// sums (each >= 0) added, is > 0: where this rank's is (ownMask_) or a
/// partial omega received from another rank is
template <int D>
void levelPlanner<D>::findCoefficientNodes()
{
    const int per = omegaPerNode_;
    std::vector<std::uint64_t>& cn = L_.coefficientNodes;
    if (L_.ownIsView) cn = ownMask_;
    else
    {
        cn.assign(std::size_t(L_.view.size())*per, 0);
        for (std::int64_t o = 0; o < nOwn_; ++o)
            for (int j = 0; j < per; ++j) cn[ownToView_[o]*per + j] |= ownMask_[o*per + j];
    }
    for (int r = 0; r < nRanks_; ++r)
    {
        const std::vector<double>& og = omegaFrom_[r];
        for (std::size_t t = 0; t < L_.tilesFrom[r].size(); ++t)
            for (int n = 0; n < npt; ++n)
                for (int j = 0; j < per; ++j)
                    if (og[(t*npt + n)*per + j] > 0) cn[L_.tilesFrom[r][t]*per + j] |= std::uint64_t(1) << n;
    }
}

/// What the fits read of 1/omega after the plan: on plain levels runScales,
/// in place of the full array (kept on chunked and tree levels, dropped on
/// separated ones)
template <int D>
void levelPlanner<D>::keepOmega()
{
    const int per = omegaPerNode_;
    if (L_.chunked || L_.tree) return;
    if (!L_.separated)
    {
        std::size_t n = 0;
        for (const auto& r : L_.coefficientRuns) n += std::size_t(r.second)*per;
        L_.runScales.assign(n, 0.0);
        double* to = L_.runScales.data();
        for (const auto& r : L_.coefficientRuns)
            to = std::copy(L_.invOmega.data() + r.first*per, L_.invOmega.data() + (r.first + r.second)*per, to);
    }
    hugeVector<double>().swap(L_.invOmega);
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
    // (1/omega is the plan's largest array while it is made)
    std::vector<std::uint8_t> done(n);
    const auto permute = [&](auto& v, std::size_t per) {
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
    permute(L_.invOmega, std::size_t(npt*omegaPerNode_));
    permute(loneNodes_, std::size_t(npt));
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

/// levelPlan::coefficientRuns from coefficientNodes, less the lone points'
/// nodes (loneNodes_)
template <int D>
void levelPlanner<D>::findCoefficientRuns()
{
    const int per = omegaPerNode_;
    const std::int64_t nNodes = L_.storedTiles*npt;
    const auto coefficient = [&](std::int64_t n) {
        std::uint64_t any = 0;
        for (int j = 0; j < per; ++j) any |= L_.coefficientNodes[(n/npt)*per + j];
        return (any >> (n % npt) & 1) != 0;
    };
    auto& runs = L_.coefficientRuns;
    for (std::int64_t n = 0; n < nNodes; ++n)
    {
        if ((!loneNodes_.empty() && loneNodes_[n]) || !coefficient(n)) continue;
        if (!runs.empty() && runs.back().first + runs.back().second == n) ++runs.back().second;
        else runs.emplace_back(n, 1);
    }
    // (where most nodes have coefficients, one sweep over all is faster
    // than the runs; not over the lone points' nodes)
    std::int64_t inRuns = 0;
    for (const auto& r : runs) inRuns += r.second;
    if (2*inRuns > nNodes && loneNodes_.empty()) runs.assign(1, {0, nNodes});
}

/// This rank's tiles, the tiles of each control point's stencil (found once:
/// for omega, the ghosts and the fits) and the nodes where its partial
/// omega is > 0 (ownMask_)
template <int D>
void levelPlanner<D>::ownTiles()
{
    ctrl_.forEachStencil(L_.scale, [&](std::size_t, const stencil<D>& st) { insertStencil(L_.ownLayout, st); });
    nOwn_ = L_.ownLayout.size();
    ownIds_.resize(ctrl_.order.size());
    const int per = omegaPerNode_;
    ownMask_.assign(std::size_t(nOwn_)*per, 0);
    std::size_t pos = 0;
    ctrl_.forEachStencil(L_.scale, [&](std::size_t i, const stencil<D>& st) {
        stencilTiles<D>& tid = ownIds_[pos++];
        findTiles(L_.ownLayout, st, tid);
        const auto nodes = detail::positiveNodes(st);
        for (int t = 0; t < (1 << D); ++t)
        {
            if (tid[t] < 0) continue;
            for (int c = 0; c < per; ++c)
                if (per == 1 || ctrl_.mask[i*nc_ + c]) ownMask_[std::size_t(tid[t])*per + c] |= nodes[t];
        }
    });
}

/// The own tiles other ranks asked for (wanted: per rank its keys, each
/// followed by the nodes it reads there): their ids (tilesTo, own ids until
/// the view is assembled) and the nodes asked (asked_)
template <int D>
void levelPlanner<D>::findAskedTiles(const std::vector<std::vector<std::uint64_t>>& wanted)
{
    for (int r = 0; r < nRanks_; ++r)
        for (std::size_t j = 0; j + 1 < wanted[r].size(); j += 2)
        {
            const std::int64_t id = L_.ownLayout.findKey(wanted[r][j]);
            if (id < 0) continue;
            L_.tilesTo[r].push_back(id);
            asked_[r].push_back(wanted[r][j + 1]);
        }
}

/// Whether an evaluation point of some rank reads the level (isRead) by its
/// coefficient tiles alone (planLevel): the own tiles with ownMask_ and, on
/// several ranks, the tiles this rank asked for with their owners' masks at
/// the nodes it asked (answered from tilesTo and asked_). Collective
template <int D>
bool levelPlanner<D>::readByEvaluation(const std::function<bool(const levelPlan<D>&)>& isRead)
{
    const int per = omegaPerNode_;
    levelPlan<D> c;
    c.level = L_.level;
    c.scale = L_.scale;
    if (nRanks_ == 1)
    {
        // (lent, and given back below)
        c.view = std::move(L_.ownLayout);
        c.coefficientNodes = std::move(ownMask_);
    }
    else
    {
        c.view = L_.ownLayout;
        c.coefficientNodes = ownMask_;
        // each tile asked for that this rank holds: its key, then per omega
        // value its nodes among those asked
        std::vector<std::vector<std::uint64_t>> answer(nRanks_);
        for (int r = 0; r < nRanks_; ++r)
            for (std::size_t j = 0; j < L_.tilesTo[r].size(); ++j)
            {
                const std::int64_t id = L_.tilesTo[r][j];
                answer[r].push_back(L_.ownLayout.keyOf(id));
                for (int m = 0; m < per; ++m) answer[r].push_back(ownMask_[id*per + m] & asked_[r][j]);
            }
        for (const auto& g : comm_.exchange(answer))
            for (std::size_t j = 0; j < g.size(); j += 1 + per)
            {
                const std::int64_t id = c.view.findOrInsertKey(g[j]);
                c.coefficientNodes.resize(std::size_t(c.view.size())*per, 0);
                for (int m = 0; m < per; ++m) c.coefficientNodes[id*per + m] |= g[j + 1 + m];
            }
    }
    const bool read = comm_.max(isRead(c) ? 1.0 : 0.0) > 0;
    if (nRanks_ == 1)
    {
        L_.ownLayout = std::move(c.view);
        ownMask_ = std::move(c.coefficientNodes);
    }
    return read;
}

/// This rank's partial omega on its own tiles
template <int D>
void levelPlanner<D>::ownOmega()
{
    const int per = omegaPerNode_;
    ownOmega_.assign(nOwn_*npt*per, 0.0);
    double* omega = ownOmega_.data();
    std::size_t pos = 0;
    ctrl_.forEachStencil(L_.scale, [&](std::size_t i, const stencil<D>& st) {
        if (per == 1)
        {
            detail::visitStencil(ownIds_[pos++], st, [&](std::int64_t id, int n, double w) {
                omega[id*npt + n] += w*w;
            });
            return;
        }
        const std::uint8_t* m = &ctrl_.mask[i*nc_];
        detail::visitStencil(ownIds_[pos++], st, [&](std::int64_t id, int n, double w) {
            double* o = omega + (id*npt + n)*per;
            for (int c = 0; c < per; ++c) if (m[c]) o[c] += w*w;
        });
    });
}

/// Of the own tiles other ranks asked for (tilesTo, asked_ from
/// findAskedTiles), the nodes whose partial sums tiles would carry
/// (nodesTo); then how the sums go (chooseGhosts), and to each asking rank
/// the answer: ghosts or tiles, the keys of the tiles this rank holds with
/// their nodesTo, their partial omega, and the ghosts
template <int D>
void levelPlanner<D>::answerRequests()
{
    L_.nodesTo.assign(nRanks_, {});
    const int blk = npt*omegaPerNode_;
    for (int r = 0; r < nRanks_; ++r)
        for (std::size_t j = 0; j < L_.tilesTo[r].size(); ++j)
            L_.nodesTo[r].push_back(asked_[r][j] & ownNodes(L_.tilesTo[r][j]));
    const std::vector<std::vector<double>> gx = chooseGhosts();
    std::vector<std::vector<std::uint64_t>> answer(nRanks_);
    std::vector<std::vector<double>> om(nRanks_);
    for (int r = 0; r < nRanks_; ++r)
    {
        if (L_.tilesTo[r].empty()) continue;
        answer[r].push_back(L_.byGhostsTo[r]);
        for (std::size_t j = 0; j < L_.tilesTo[r].size(); ++j)
        {
            const std::int64_t id = L_.tilesTo[r][j];
            answer[r].insert(answer[r].end(), {L_.ownLayout.keyOf(id), L_.nodesTo[r][j]});
            om[r].insert(om[r].end(), ownOmega_.begin() + id*blk, ownOmega_.begin() + (id + 1)*blk);
        }
    }
    const std::vector<std::vector<std::uint64_t>> got = comm_.exchange(answer);
    L_.byGhostsFrom.assign(nRanks_, 0);
    L_.nodesFrom.assign(nRanks_, {});
    for (int r = 0; r < nRanks_; ++r)
    {
        if (got[r].empty()) continue;
        L_.byGhostsFrom[r] = std::uint8_t(got[r][0]);
        for (std::size_t j = 1; j + 1 < got[r].size(); j += 2)
        {
            keysFrom_[r].push_back(got[r][j]);
            L_.nodesFrom[r].push_back(got[r][j + 1]);
        }
    }
    omegaFrom_ = comm_.exchange(om);
    L_.ghostsFrom = comm_.exchange(gx);
}

/// Ghost mode towards r when this rank's points that reach the nodes r
/// asked for are fewer than the nodes whose partial sums the tiles would
/// carry (nc values each per apply); their coordinates and mask flags are
/// sent once (returned, per rank). r then forms this rank's partial sums at
/// the nodes it reads; it reads no other of the tiles. Where no point
/// reaches them, ghost mode sends nothing.
template <int D>
std::vector<std::vector<double>> levelPlanner<D>::chooseGhosts()
{
    L_.ghostsTo.assign(nRanks_, {});
    L_.byGhostsTo.assign(nRanks_, 0);
    std::vector<std::vector<double>> gx(nRanks_);
    std::vector<std::uint64_t> asked(nOwn_);
    for (int r = 0; r < nRanks_; ++r)
    {
        if (L_.tilesTo[r].empty()) continue;
        std::fill(asked.begin(), asked.end(), 0);
        for (std::size_t j = 0; j < L_.tilesTo[r].size(); ++j) asked[L_.tilesTo[r][j]] = asked_[r][j];
        const std::size_t tileValues = std::size_t(nodeCount(L_.nodesTo[r]));   // nodes, as tiles would carry them
        const auto reaches = [&](std::size_t q) {
            bool tile = false;
            for (const std::int32_t id : ownIds_[q]) tile = tile || (id >= 0 && asked[id]);
            if (!tile) return false;
            const stencil<D> st = ctrl_.stencilAt(q, L_.scale);
            const indexBox<D> tb = st.tiles();
            for (int c = 0; c < (1 << D); ++c)
            {
                const std::int32_t id = ownIds_[q][c];
                if (id >= 0 && (asked[id] & st.nodesIn(stencilTile<D>(tb, c))) != 0) return true;
            }
            return false;
        };
        std::vector<std::uint32_t> g;
        std::vector<std::size_t> at;   // each ghost's position in order
        for (std::size_t q = 0; q < ctrl_.order.size() && g.size() < tileValues; ++q)
            if (reaches(q)) { g.push_back(ctrl_.order[q]); at.push_back(q); }
        if (g.size() >= tileValues) continue;
        L_.byGhostsTo[r] = 1;
        for (std::size_t k = 0; k < g.size(); ++k)
        {
            const std::uint32_t i = g[k];
            gx[r].insert(gx[r].end(), ctrl_.x[i], ctrl_.x[i] + D);
            for (int c = 0; c < nc_; ++c) gx[r].push_back(ctrl_.constrains(i, c) ? 1.0 : 0.0);
            // it continues the previous ghost's run of equal stencils (the
            // apply's runs: the point after it in order, with the same nodes)
            const bool continues = k > 0 && at[k] == at[k - 1] + 1
                && ctrl_.stencilAt(at[k], L_.scale).base == ctrl_.stencilAt(at[k - 1], L_.scale).base;
            gx[r].push_back(continues ? 1.0 : 0.0);
        }
        L_.ghostsTo[r] = std::move(g);
    }
    return gx;
}

/// The view: own and received tiles, dense when that is not much larger;
/// tilesTo and tilesFrom as view ids, the own tiles shared with lower ranks
template <int D>
void levelPlanner<D>::assembleView()
{
    std::int64_t upper = nOwn_;
    for (const auto& kg : keysFrom_) upper += std::int64_t(kg.size());
    std::int64_t denseTiles = 1;
    for (int d = 0; d < D; ++d) denseTiles *= (nodes_[d] + tileEdge - 1)/tileEdge;
    const bool dense = denseTiles <= 2*upper + 64;
    if (nRanks_ == 1 && !dense)
    {
        // Serial and sparse: the own tiles and partial omega are the view
        L_.view = std::move(L_.ownLayout);
        L_.ownLayout = tileLayout<D>();
        L_.ownIsView = true;
        L_.invOmega = std::move(ownOmega_);
        return;
    }
    L_.view.init(nodes_, dense);
    ownToView_.resize(nOwn_);
    std::vector<std::int64_t>& ownToView = ownToView_;
    for (std::int64_t id = 0; id < nOwn_; ++id) ownToView[id] = L_.view.findOrInsertKey(L_.ownLayout.keyOf(id));
    for (int r = 0; r < nRanks_; ++r)
        for (auto key : keysFrom_[r]) L_.tilesFrom[r].push_back(L_.view.findOrInsertKey(key));
    for (auto& tiles : L_.tilesTo)
        for (auto& id : tiles) id = ownToView[id];
    std::vector<std::uint8_t> shared(L_.view.size(), 0);
    for (std::int64_t id = 0; id < nOwn_; ++id) shared[ownToView[id]] = 1;
    for (int r = 0; r < me_; ++r)
        for (auto id : L_.tilesFrom[r])
            if (shared[id] == 1) { shared[id] = 2; L_.sharedWithLower.push_back(id); }
    sumOmega(ownToView);
}

/// omega on the view: the ranks' partial sums added in rank order
template <int D>
void levelPlanner<D>::sumOmega(const std::vector<std::int64_t>& ownToView)
{
    const int blk = npt*omegaPerNode_;
    L_.invOmega.assign(L_.view.size()*blk, 0.0);
    for (int r = 0; r < nRanks_; ++r)
    {
        if (r == me_)
        {
            for (std::int64_t id = 0; id < nOwn_; ++id)
                for (int j = 0; j < blk; ++j) L_.invOmega[ownToView[id]*blk + j] += ownOmega_[id*blk + j];
        }
        else
        {
            const auto& og = omegaFrom_[r];
            for (std::size_t t = 0; t < L_.tilesFrom[r].size(); ++t)
                for (int j = 0; j < blk; ++j) L_.invOmega[L_.tilesFrom[r][t]*blk + j] += og[t*blk + j];
        }
    }
}

/// The view tiles of the own control points' stencils
template <int D>
void levelPlanner<D>::findControlTiles()
{
    if (L_.ownIsView)
    {
        L_.controlTiles = std::move(ownIds_);
        return;
    }
    L_.controlTiles.resize(ctrl_.order.size());
    std::size_t pos = 0;
    ctrl_.forEachStencil(L_.scale, [&](std::size_t, const stencil<D>& st) {
        findTiles(L_.view, st, L_.controlTiles[pos++]);
    });
}

/// Whether own point q (stencil st) is alone at every node of its stencil:
/// in every component it constrains, omega (the sum over all ranks, not yet
/// inverted) is its own w^2 alone, summed as the plan summed it (0 + w*w:
/// exact), also at nodes where its weight is 0; with freeZero, omega is 0
/// in the components it leaves free
template <int D>
bool levelPlanner<D>::aloneAtNodes(std::size_t q, const stencil<D>& st, bool freeZero) const
{
    const std::size_t i = ctrl_.order[q];
    bool alone = true;
    detail::visitStencil(L_.controlTiles[q], st, [&](std::int64_t id, int n, double w) {
        const double* o = &L_.invOmega[(id*npt + n)*omegaPerNode_];
        for (int c = 0; c < omegaPerNode_; ++c)
        {
            const bool constrained = omegaPerNode_ == 1 || ctrl_.mask[i*nc_ + c];
            if (constrained || freeZero) alone = alone && o[c] == (constrained ? w*w : 0.0);
        }
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
    std::vector<stencil<D>> st(nq);
    for (std::size_t q = 0; q < nq; ++q) st[q] = ctrl_.stencilAt(q, L_.scale);
    L_.lone.assign(nq, 0);
    loneNodes_.clear();
    for (std::size_t q = 0; q < nq; ++q)
    {
        if ((q > 0 && st[q - 1].base == st[q].base) || (q + 1 < nq && st[q + 1].base == st[q].base)) continue;
        bool alone = true;
        for (const std::int32_t id : L_.controlTiles[q]) alone = alone && !(id >= 0 && !read.empty() && read[id]);
        alone = alone && aloneAtNodes(q, st[q], true);
        L_.lone[q] = alone;
        if (!alone) continue;
        loneNodes_.resize(std::size_t(L_.view.size())*npt, 0);
        detail::visitStencil(L_.controlTiles[q], st[q], [&](std::int64_t id, int n, double) { loneNodes_[id*npt + n] = 1; });
    }
    if (loneNodes_.empty()) L_.lone.clear();
}

/// The ghosts' stencil tiles, numbered as the tiles received from their rank
template <int D>
void levelPlanner<D>::findGhostTiles()
{
    L_.ghostTiles.assign(nRanks_, {});
    L_.ghostStencils.assign(nRanks_, {});
    L_.ghostScales.assign(nRanks_, {});
    for (int r = 0; r < nRanks_ && nRanks_ > 1; ++r)
    {
        if (L_.ghostsFrom[r].empty()) continue;
        std::vector<std::int32_t> at(L_.view.size(), -1);
        for (std::size_t t = 0; t < L_.tilesFrom[r].size(); ++t) at[L_.tilesFrom[r][t]] = std::int32_t(t);
        const std::size_t stride = D + nc_ + 1, ng = L_.ghostsFrom[r].size()/stride;
        L_.ghostTiles[r].resize(ng);
        for (std::size_t g = 0; g < ng; ++g)
        {
            stencilTiles<D>& tid = L_.ghostTiles[r][g];
            const stencil<D> st = levelStencil<D>(dom_.local0(&L_.ghostsFrom[r][g*stride]), L_.scale);
            findTiles(L_.view, st, tid);
            for (std::int32_t& id : tid) if (id >= 0) id = at[id];
            L_.ghostStencils[r].push_back(L_.separated ? st : st.cubedWeights());
            L_.ghostScales[r].push_back(1/st.sumSquares());
        }
    }
}

template <int D>
void levelPlanner<D>::fillStats()
{
    const levelPlan<D>& L = L_;
    levelStats& s = L_.stats;
    s.level = L.level;
    s.h = dom_.h0/L.scale;
    s.ownTiles = L.ownTiles().size();
    s.viewTiles = L.view.size();
    s.dense = L.view.dense();
    s.separated = L.separated;
    for (const std::uint8_t l : L.lone) s.lonePoints += l;
    s.chunked = L.chunked;
    s.tree = L.tree;
    s.nodes = L.storedTiles*npt;
    // (phi as the first apply allocates it)
    s.bytes = std::int64_t((L.coefficientCount(nc_) + L.invOmega.capacity() + L.runScales.capacity()
                            + L.loneResiduals.capacity())*sizeof(double)
        + (L.lonePoints.capacity() + L.loneTileStart.capacity() + L.loneOnTile.capacity())*sizeof(std::uint32_t)
        + L.coefficientNodes.capacity()*sizeof(std::uint64_t)
        + L.ownLayout.bytes() + L.view.bytes() + L.sharedWithLower.capacity()*sizeof(std::int64_t)
        + L.controlTiles.capacity()*sizeof(stencilTiles<D>) + L.readEveryFit.capacity()
        + L.scaledResiduals.capacity()*sizeof(double)
        + L.coefficientRuns.capacity()*sizeof(L.coefficientRuns[0]) + L.lone.capacity());
    if (L.tree)
    {
        const treeTraffic t = treeTrafficOf(nRanks_, me_, std::size_t(L.treeValues));
        s.messagesSent += t.messagesSent;
        s.messagesReceived += t.messagesReceived;
        s.bytesSentPerApply += t.valuesSent*std::int64_t(sizeof(double));
        s.bytesReceivedPerApply += t.valuesReceived*std::int64_t(sizeof(double));
        s.bytes += std::int64_t((L.treeStart.capacity() + L.ownInView.capacity())*sizeof(std::int64_t)
            + L.treeNodes.capacity()*sizeof(std::uint64_t));
        return;
    }
    if (L.chunked)
    {
        const chunkExchange& X = L.chunks;
        for (int r = 0; r < nRanks_; ++r)
        {
            const std::int64_t out = runValues(X.partialTo[r], nc_) + runValues(X.fullTo[r], nc_);
            const std::int64_t in = std::int64_t(X.partialCounts[r] + X.fullCounts[r]);
            s.messagesSent += !X.partialTo[r].empty() + !X.fullTo[r].empty();
            s.messagesReceived += (X.partialCounts[r] > 0) + (X.fullCounts[r] > 0);
            s.bytesSentPerApply += out*std::int64_t(sizeof(double));
            s.bytesReceivedPerApply += in*std::int64_t(sizeof(double));
            s.tilesSent += std::int64_t(L.tilesTo[r].size());
            s.tilesReceived += std::int64_t(L.tilesFrom[r].size());
        }
        s.bytes += std::int64_t(X.terms.capacity()*sizeof(chunkTerm) + X.termsBegin.capacity()*sizeof(std::int64_t)
            + (X.owned.capacity() + X.termRuns.capacity())*sizeof(nodeRun));
        for (int r = 0; r < nRanks_; ++r)
            s.bytes += std::int64_t((X.partialTo[r].capacity() + X.fullTo[r].capacity() + X.fullFrom[r].capacity())
                *sizeof(nodeRun));
        return;
    }
    for (int r = 0; r < nRanks_ && nRanks_ > 1; ++r)
    {
        s.tilesSent += std::int64_t(L.tilesTo[r].size());
        s.tilesReceived += std::int64_t(L.tilesFrom[r].size());
        s.ghostsSent += std::int64_t(L.ghostsTo[r].size());
        s.ghostsReceived += std::int64_t(L.ghostTiles[r].size());
        const std::int64_t vs = (L.byGhostsTo[r] ? std::int64_t(L.ghostsTo[r].size()) : nodeCount(L.nodesTo[r]))*nc_;
        s.messagesSent += vs > 0;
        s.messagesReceived += L.receiveCounts[r] > 0;
        s.bytesSentPerApply += vs*std::int64_t(sizeof(double));
        s.bytesReceivedPerApply += std::int64_t(L.receiveCounts[r]*sizeof(double));
        s.bytes += std::int64_t((L.nodesTo[r].capacity() + L.nodesFrom[r].capacity())*sizeof(std::uint64_t));
        s.bytes += std::int64_t((L.ghostsFrom[r].capacity() + L.ghostScales[r].capacity())*sizeof(double)
            + L.ghostTiles[r].capacity()*sizeof(stencilTiles<D>) + L.ghostStencils[r].capacity()*sizeof(stencil<D>));
    }
}

template <int D>
levelPlan<D> planLevel(int k, const communicator& comm, const domain<D>& dom, const controlPoints<D>& ctrl,
                       const queryClusters<D>& clusters, int bucketTiles, params::exchangeMode mode,
                       const std::function<bool(const levelPlan<D>&)>& isRead)
{
    return levelPlanner<D>(comm, dom, ctrl, clusters, bucketTiles, mode).run(k, isRead);
}

template levelPlan<2> planLevel<2>(int, const communicator&, const domain<2>&, const controlPoints<2>&,
                                   const queryClusters<2>&, int, params::exchangeMode,
                                   const std::function<bool(const levelPlan<2>&)>&);
template levelPlan<3> planLevel<3>(int, const communicator&, const domain<3>&, const controlPoints<3>&,
                                   const queryClusters<3>&, int, params::exchangeMode,
                                   const std::function<bool(const levelPlan<3>&)>&);

} // namespace mba
