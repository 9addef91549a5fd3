// The planning of a level in the steps that levelPlanner::run() takes in
// order (the query clusters and whom a rank asks for which tiles:
// levelPlanRequests.cpp; the points alone at their nodes:
// levelPlanLone.cpp; the choice of the level's exchange:
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
    // omega is formed only where it is read: this rank's partial sums on the
    // tiles other ranks ask for (answerRequests), the sums where two or more
    // points meet (the lone test), then on the tiles that keep coefficients
    // (on a fine level of a graded mesh most tiles hold only lone points')
    L_.tilesFrom.assign(nRanks_, {});
    keysFrom_.assign(nRanks_, {});
    omegaFrom_.assign(nRanks_, {});
    maskFrom_.assign(nRanks_, {});
    if (nRanks_ > 1) answerRequests();
    assembleView();
    findControlTiles();
    findCoefficientNodes();
    omegaWhereShared();
    testSeparation();
    if (!L_.separated) findLonePoints();
    std::vector<std::uint64_t>().swap(multiNodes_);
    std::vector<std::int32_t>().swap(omegaSlot_);
    // (a dense view's omega is formed on every tile for the lone test, and kept)
    if (L_.separated || !L_.view.dense()) hugeVector<double>().swap(omega_);
    findGhostTiles();
    L_.receiveCounts.assign(nRanks_, 0);
    for (int r = 0; r < nRanks_ && nRanks_ > 1; ++r)
        L_.receiveCounts[r] = nc_*(L_.byGhostsFrom[r] ? L_.ghostTiles[r].size()
                                                      : std::size_t(nodeCount(L_.nodesFrom[r])));
    if (nRanks_ > 1) chooseExchange();
    L_.storedTiles = L_.view.size();
    const bool plain = !L_.separated && !L_.chunked && !L_.tree;
    if (plain && !L_.lone.empty() && !L_.view.dense()) storeLoneTilesLast();
    if (!L_.separated)
    {
        const std::int64_t n = L_.storedTiles;
        if (!L_.view.dense()) formOmega(n, [n](std::int64_t id) { return id < n ? id : -1; });
        L_.invOmega = std::move(omega_);
    }
    for (double& o : L_.invOmega) o = o > 0 ? 1/o : 0.0;
    if (plain) findCoefficientRuns();
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

/// levelPlan::coefficientRuns from coefficientNodes, less the lone points'
/// nodes (loneNodes_)
template <int D>
void levelPlanner<D>::findCoefficientRuns()
{
    const std::int64_t nNodes = L_.storedTiles*npt;
    const auto coefficient = [&](std::int64_t n) {
        return (anyValue(L_.coefficientNodes, n/npt) >> (n % npt) & 1) != 0;
    };
    auto& runs = L_.coefficientRuns;
    for (std::int64_t n = 0; n < nNodes; ++n)
    {
        if ((!loneNodes_.empty() && (loneNodes_[n/npt] >> (n % npt) & 1)) || !coefficient(n)) continue;
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
/// omega is > 0 (ownMask_), with two or more points' w^2 (ownMulti_)
template <int D>
void levelPlanner<D>::ownTiles()
{
    ctrl_.forEachStencil(L_.scale, [&](std::size_t, const stencil<D>& st) { insertStencil(L_.ownLayout, st); });
    nOwn_ = L_.ownLayout.size();
    ownIds_.resize(ctrl_.order.size());
    const int per = omegaPerNode_;
    ownMask_.assign(std::size_t(nOwn_)*per, 0);
    ownMulti_.assign(ownMask_.size(), 0);
    std::size_t pos = 0;
    ctrl_.forEachStencil(L_.scale, [&](std::size_t i, const stencil<D>& st) {
        stencilTiles<D>& tid = ownIds_[pos++];
        findTiles(L_.ownLayout, st, tid);
        const auto nodes = detail::positiveNodes(st);
        for (int t = 0; t < (1 << D); ++t)
        {
            if (tid[t] < 0) continue;
            for (int c = 0; c < per; ++c)
            {
                if (per > 1 && !ctrl_.mask[i*nc_ + c]) continue;
                const std::size_t j = std::size_t(tid[t])*per + c;
                ownMulti_[j] |= ownMask_[j] & nodes[t];
                ownMask_[j] |= nodes[t];
            }
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

/// This rank's partial omega (omega_) on nSlots tiles: the points' stencil
/// tiles (tiles, in order) at slot(id), none where that is < 0
template <int D>
template <class Slot>
void levelPlanner<D>::ownOmega(const std::vector<stencilTiles<D>>& tiles, std::int64_t nSlots, Slot slot)
{
    const int per = omegaPerNode_;
    omega_.assign(nSlots*npt*per, 0.0);
    double* omega = omega_.data();
    std::size_t pos = 0;
    ctrl_.forEachStencil(L_.scale, [&](std::size_t i, const stencil<D>& st) {
        if (per == 1)
        {
            detail::visitStencil(tiles[pos++], st, [&](std::int64_t id, int n, double w) {
                const std::int64_t s = slot(id);
                if (s >= 0) omega[s*npt + n] += w*w;
            });
            return;
        }
        const std::uint8_t* m = &ctrl_.mask[i*nc_];
        detail::visitStencil(tiles[pos++], st, [&](std::int64_t id, int n, double w) {
            const std::int64_t s = slot(id);
            if (s < 0) return;
            double* o = omega + (s*npt + n)*per;
            for (int c = 0; c < per; ++c) if (m[c]) o[c] += w*w;
        });
    });
}

/// omega (omega_, not inverted) on nSlots view tiles, at slot(id) of view
/// tile id (none where that is < 0): the ranks' partial sums added in rank
/// order, each formed from 0 (every rank holding a tile adds the same terms
/// in the same order)
template <int D>
template <class Slot>
void levelPlanner<D>::formOmega(std::int64_t nSlots, Slot slot)
{
    ownOmega(L_.controlTiles, nSlots, slot);
    if (nRanks_ == 1) return;
    const std::int64_t blk = npt*omegaPerNode_;
    // the lower ranks' sum, where they have partial sums, before this rank's
    std::vector<std::int32_t> lowerAt(nSlots, -1);
    std::vector<double> lower;
    for (int r = 0; r < me_; ++r)
        for (std::size_t t = 0; t < L_.tilesFrom[r].size(); ++t)
        {
            const std::int64_t s = slot(L_.tilesFrom[r][t]);
            if (s < 0) continue;
            if (lowerAt[s] < 0)
            {
                lowerAt[s] = std::int32_t(lower.size()/blk);
                lower.resize(lower.size() + blk, 0.0);
            }
            for (std::int64_t j = 0; j < blk; ++j) lower[lowerAt[s]*blk + j] += omegaFrom_[r][t*blk + j];
        }
    for (std::int64_t s = 0; s < nSlots; ++s)
        if (lowerAt[s] >= 0)
            for (std::int64_t j = 0; j < blk; ++j) omega_[s*blk + j] = lower[lowerAt[s]*blk + j] + omega_[s*blk + j];
    for (int r = me_ + 1; r < nRanks_; ++r)
        for (std::size_t t = 0; t < L_.tilesFrom[r].size(); ++t)
        {
            const std::int64_t s = slot(L_.tilesFrom[r][t]);
            if (s >= 0) for (std::int64_t j = 0; j < blk; ++j) omega_[s*blk + j] += omegaFrom_[r][t*blk + j];
        }
}

/// omega (omega_, omegaSlot_) on the view tiles where two or more points'
/// w^2 are > 0, the only nodes where aloneAtNodes needs its value
/// (elsewhere it is a point's own w^2, or 0); on a dense view on all tiles
/// (every tile is stored)
template <int D>
void levelPlanner<D>::omegaWhereShared()
{
    const std::int64_t n = L_.view.size();
    omegaSlot_.assign(n, -1);
    std::int32_t m = 0;
    for (std::int64_t id = 0; id < n; ++id)
        if (L_.view.dense() || anyValue(multiNodes_, id)) omegaSlot_[id] = m++;
    formOmega(m, [this](std::int64_t id) { return std::int64_t(omegaSlot_[id]); });
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
            L_.nodesTo[r].push_back(asked_[r][j] & anyValue(ownMask_, L_.tilesTo[r][j]));
    const std::vector<std::vector<double>> gx = chooseGhosts();
    // this rank's partial omega on the tiles asked for (at asked[id])
    std::vector<std::int64_t> asked(nOwn_, -1);
    std::int64_t nAsked = 0;
    for (const auto& tiles : L_.tilesTo)
        for (const std::int64_t id : tiles) if (asked[id] < 0) asked[id] = nAsked++;
    ownOmega(ownIds_, nAsked, [&asked](std::int64_t id) { return asked[id]; });
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
            om[r].insert(om[r].end(), omega_.begin() + asked[id]*blk, omega_.begin() + (asked[id] + 1)*blk);
        }
    }
    hugeVector<double>().swap(omega_);
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
    const int per = omegaPerNode_;
    maskFrom_.assign(nRanks_, {});
    for (int r = 0; r < nRanks_; ++r)
        for (std::size_t j = 0; j < omegaFrom_[r].size()/npt; ++j)   // (per tile and omega value)
        {
            const std::size_t t = j/per, c = j % per;
            std::uint64_t nodes = 0;
            for (int n = 0; n < npt; ++n) if (omegaFrom_[r][(t*npt + n)*per + c] > 0) nodes |= std::uint64_t(1) << n;
            maskFrom_[r].push_back(nodes);
        }
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

/// Whether the view is dense: the level's box of tiles is not much more
/// than the own and received tiles
template <int D>
bool levelPlanner<D>::viewIsDense() const
{
    std::int64_t upper = nOwn_;
    for (const auto& kg : keysFrom_) upper += std::int64_t(kg.size());
    std::int64_t denseTiles = 1;
    for (int d = 0; d < D; ++d) denseTiles *= (nodes_[d] + tileEdge - 1)/tileEdge;
    return denseTiles <= 2*upper + 64;
}

/// The view: own and received tiles, dense when that is not much larger;
/// tilesTo and tilesFrom as view ids, the own tiles shared with lower ranks
template <int D>
void levelPlanner<D>::assembleView()
{
    const bool dense = viewIsDense();
    if (nRanks_ == 1 && !dense)
    {
        // Serial and sparse: the own tiles are the view
        L_.view = std::move(L_.ownLayout);
        L_.ownLayout = tileLayout<D>();
        L_.ownIsView = true;
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
