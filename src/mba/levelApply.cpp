// The apply's kernels by component count (each of nc = 1, 2, 3 compiled on
// its own), then the apply's steps in the order apply() runs them.
#include "levelApply.hpp"
#include "plainLattice.hpp"
#include "treeSum.hpp"

#include <algorithm>

namespace mba {

namespace {

/// One control point's part of the partial delta: w^3 r/sum(w^2) on each node
/// of its stencil (rr = r/sum(w^2) per component), w^3 as the product of the
/// directions' cubed weights (the stencil cubed: its weights cubed). The
/// point's owner and a rank holding it as a ghost both add it through here:
/// bitwise the same sums.
template <int D>
inline void scatter(double* delta, int nc, const stencilTiles<D>& tid, const stencil<D>& cubed, const double* rr)
{
    switch (nc)
    {
        case 1: detail::scatterStencil<D, 1>(delta, tid, cubed, rr); break;
        case 2: detail::scatterStencil<D, 2>(delta, tid, cubed, rr); break;
        default: detail::scatterStencil<D, 3>(delta, tid, cubed, rr);
    }
}

/// v[n*NC + c] *= s[n] for n in [0, nNodes): one scale a node, NC values
template <int NC>
void scaleNodes(double* v, const double* s, std::size_t nNodes)
{
    for (std::size_t n = 0; n < nNodes; ++n)
        for (int c = 0; c < NC; ++c) v[n*NC + c] *= s[n];
}

/// Runs shorter than this (single points) are scattered point after point
constexpr std::size_t minRun = 2;

/// Runs at least this long are evaluated through a copy of their stencil's
/// nodes (evalRun): copying them costs about what one point's sweep does
constexpr std::size_t minBlockRun = 4;

/// scatter for a run of n points whose stencils share their nodes (cubed:
/// their stencils cubed, rr: nc values a point); the sums are formed in
/// another order than point after point
template <int D>
inline void scatterRun(double* delta, int nc, const stencilTiles<D>& tid, const stencil<D>* cubed,
                       const double* rr, std::size_t n)
{
    switch (nc)
    {
        case 1: detail::scatterRun<D, 1>(delta, tid, cubed, rr, n); break;
        case 2: detail::scatterRun<D, 2>(delta, tid, cubed, rr, n); break;
        default: detail::scatterRun<D, 3>(delta, tid, cubed, rr, n);
    }
}

/// A point of a separated level (levelPlan::separated): the only one at its
/// nodes in the components it constrains (on: those, nullptr: all), so phi =
/// delta/omega = w r/sum(w^2) there is stored, in those components only.
/// The owner and a rank holding the point as a ghost both store it here.
template <int D>
void scatterSeparated(double* phi, int nc, const stencilTiles<D>& tid, const stencil<D>& st, const double* rr,
                      const bool* on)
{
    using detail::put;
    if (!on)
    {
        switch (nc)
        {
            case 1: detail::scatterStencil<D, 1, put::store>(phi, tid, st, rr); break;
            case 2: detail::scatterStencil<D, 2, put::store>(phi, tid, st, rr); break;
            default: detail::scatterStencil<D, 3, put::store>(phi, tid, st, rr);
        }
        return;
    }
    switch (nc)
    {
        case 1: detail::scatterStencil<D, 1, put::select>(phi, tid, st, rr, on); break;
        case 2: detail::scatterStencil<D, 2, put::select>(phi, tid, st, rr, on); break;
        default: detail::scatterStencil<D, 3, put::select>(phi, tid, st, rr, on);
    }
}

/// The lattice's values at a run of n points whose stencils share their
/// nodes (st: their stencils), added to out (NC a point): the stencil's nodes
/// are copied once into a plain 4^D block, which each point then reads as a
/// flat lattice (whole rows, no tiles), in vectors of W doubles
template <int D, int NC, int W>
inline __attribute__((always_inline)) void evalRunAs(const double* phi, const stencilTiles<D>& tid,
                                                     const stencil<D>* st, std::size_t n, double* out)
{
    double block[(D == 3 ? 64 : 16)*NC];
    detail::gatherStencil<D, NC>(phi, tid, st[0], block);
    indexBox<D> b;
    for (int d = 0; d < D; ++d) { b.lo[d] = st[0].base[d]; b.hi[d] = b.lo[d] + 3; }
    for (std::size_t j = 0; j < n; ++j) flatStencil<NC, W>(block, b, st[j], out + j*NC);
}

#ifdef MBA_WIDE_VECTORS
/// The same compiled for AVX2 with FMA, in vectors of four doubles
template <int D, int NC>
MBA_WIDE_TARGET void evalRunWide(const double* phi, const stencilTiles<D>& tid, const stencil<D>* st,
                                 std::size_t n, double* out)
{
    evalRunAs<D, NC, 4>(phi, tid, st, n, out);
}
#endif

template <int D>
void evalRun(const double* phi, int nc, const stencilTiles<D>& tid, const stencil<D>* st, std::size_t n,
             double* out)
{
#ifdef MBA_WIDE_VECTORS
    if (wideVectors())
    {
        switch (nc)
        {
            case 1: evalRunWide<D, 1>(phi, tid, st, n, out); break;
            case 2: evalRunWide<D, 2>(phi, tid, st, n, out); break;
            default: evalRunWide<D, 3>(phi, tid, st, n, out);
        }
        return;
    }
#endif
    switch (nc)
    {
        case 1: evalRunAs<D, 1, 2>(phi, tid, st, n, out); break;
        case 2: evalRunAs<D, 2, 2>(phi, tid, st, n, out); break;
        default: evalRunAs<D, 3, 2>(phi, tid, st, n, out);
    }
}

} // namespace

template <int D>
void levelApplier<D>::apply(levelPlan<D>& L, std::vector<double>& residuals)
{
    const std::size_t nPhi = L.coefficientCount(ctrl_.nComponents);
    if (L.phi.size() != nPhi) L.phi.assign(nPhi, 0.0);
    // delta += w^2 phi_c = w^3 r_c / sum(w^2): this rank's partial sums, in
    // the view; in parallel the other ranks' are then added in rank order.
    // Separated: phi itself is stored at the nodes of the own points that
    // are read every fit (always the same nodes; no other point writes
    // there). The other points' nodes keep older values, read by nobody
    // until storeDeferredCoefficients() stores them.
    clearLattice(L);
    computeStencils(L);
    std::vector<double>& rr = L.separated ? L.scaledResiduals : scaledResiduals_;
    scaleResiduals(rr, residuals);
    scatterOwn(L, rr);
    L.allCoefficientsStored = !L.separated;
    if (comm_.size() > 1)
    {
        if (L.chunked) exchangeChunks(L);
        else if (L.tree) exchangeInTree(L);
        else exchangePartialSums(L, residuals);
    }
    // phi = delta/omega (no contribution where omega is 0: delta is 0 there
    // too); separated levels hold phi already, chunked ones received it
    if (!L.separated && !L.chunked && !L.tree)
    {
        const double* s = L.runScales.data();
        for (const auto& r : L.coefficientRuns)
        {
            divideByOmega(L, r.first, r.second, s);
            s += r.second*ctrl_.omegaPerNode;
        }
    }
    else if (L.tree) divideByOmega(L, 0, std::int64_t(L.invOmega.size())/ctrl_.omegaPerNode, L.invOmega.data());
    keepLoneResiduals(L, rr);
    subtractLevel(L, rr, residuals);
}

/// Zero delta; of a separated level only the tiles that other ranks' values
/// are added to, of a chunked or tree one only the own tiles
template <int D>
void levelApplier<D>::clearLattice(levelPlan<D>& L) const
{
    const int blk = levelPlan<D>::npt*ctrl_.nComponents;
    const int nc = ctrl_.nComponents;
    if (L.chunked || L.tree)
    {
        for (const std::int64_t id : L.ownInView) std::fill(L.phi.data() + id*blk, L.phi.data() + (id + 1)*blk, 0.0);
    }
    else if (!L.separated)
    {
        // (the other nodes hold 0 from the plan on: nothing adds to them)
        for (const auto& r : L.coefficientRuns)
            std::fill(L.phi.data() + r.first*nc, L.phi.data() + (r.first + r.second)*nc, 0.0);
    }
    else
        for (const auto& tiles : L.tilesFrom)
            for (const std::int64_t id : tiles) std::fill(&L.phi[id*blk], &L.phi[(id + 1)*blk], 0.0);
}

/// The stencils (again for the residuals) and, for the scatter, their cubed
/// weights, in a pass of their own: the scatter's vector loads then read
/// weights stored long before (loads of values just stored in smaller
/// pieces stall until the stores retire)
template <int D>
void levelApplier<D>::computeStencils(const levelPlan<D>& L)
{
    const std::size_t nq = ctrl_.order.size();
    stencils_.resize(nq);
    cubedStencils_.resize(L.separated ? 0 : nq);
    for (std::size_t q = 0; q < nq; ++q)
    {
        stencils_[q] = ctrl_.stencilAt(q, L.scale);
        if (!L.separated) cubedStencils_[q] = stencils_[q].cubedWeights();
    }
}

/// rr = r/sum(w^2) per point in order x component (0 where not constrained)
template <int D>
void levelApplier<D>::scaleResiduals(std::vector<double>& rr, const std::vector<double>& residuals) const
{
    const std::size_t nq = ctrl_.order.size();
    const int nc = ctrl_.nComponents;
    rr.resize(nq*nc);
    for (std::size_t q = 0; q < nq; ++q)
    {
        const std::size_t i = ctrl_.order[q];
        const double isw = 1/stencils_[q].sumSquares();
        for (int c = 0; c < nc; ++c)
            rr[q*nc + c] = ctrl_.constrains(i, c) ? residuals[i*nc + c]*isw : 0.0;
    }
}

/// This rank's partial sums delta (separated: phi at the points read every
/// fit), but for the lone points'. Runs of points with the same stencil
/// nodes at once (coarse levels), short runs point after point: as the
/// ranks holding them as ghosts form their sums (ghostPartialSums)
template <int D>
void levelApplier<D>::scatterOwn(levelPlan<D>& L, const std::vector<double>& rr) const
{
    const std::size_t nq = ctrl_.order.size();
    const int nc = ctrl_.nComponents;
    if (L.separated)
    {
        for (std::size_t q = 0; q < nq; ++q)
        {
            bool on[3];
            if (L.readEveryFit[q])
                scatterSeparated<D>(L.phi.data(), nc, L.controlTiles[q], stencils_[q], &rr[q*nc],
                                    ctrl_.constrained(ctrl_.order[q], on));
        }
        return;
    }
    for (std::size_t q = 0, e; q < nq; q = e)
    {
        for (e = q + 1; e < nq && stencils_[e].base == stencils_[q].base; ++e) {}
        if (e - q >= minRun)
            scatterRun<D>(L.phi.data(), nc, L.controlTiles[q], &cubedStencils_[q], &rr[q*nc], e - q);
        else if (L.lone.empty() || !L.lone[q])
            for (std::size_t j = q; j < e; ++j)
                scatter<D>(L.phi.data(), nc, L.controlTiles[j], cubedStencils_[j], &rr[j*nc]);
    }
}

/// The lone points' r/sum(w^2) (levelPlan::loneResiduals), from which the
/// evaluations form their part of the level's values (their coefficients
/// are not stored)
template <int D>
void levelApplier<D>::keepLoneResiduals(levelPlan<D>& L, const std::vector<double>& rr) const
{
    const int nc = ctrl_.nComponents;
    for (std::size_t j = 0; j < L.lonePoints.size(); ++j)
        std::copy_n(&rr[std::size_t(L.lonePoints[j])*nc], nc, &L.loneResiduals[j*nc]);
}

/// Exchange the partial delta at the requested tiles' nodes (nodesTo), or
/// the residuals of the ghosts, and add the ranks' partial sums in rank order
template <int D>
void levelApplier<D>::exchangePartialSums(levelPlan<D>& L, const std::vector<double>& residuals)
{
    constexpr int npt = levelPlan<D>::npt;
    const int P = comm_.size(), nc = ctrl_.nComponents;
    send_.resize(P);
    recv_.resize(P);
    ghostSums_.resize(P);
    for (int r = 0; r < P; ++r)
    {
        send_[r].clear();
        recv_[r].resize(L.receiveCounts[r]);
        if (L.byGhostsTo[r])
        {
            for (const std::uint32_t i : L.ghostsTo[r])
                send_[r].insert(send_[r].end(), &residuals[i*nc], &residuals[i*nc] + nc);
            continue;
        }
        for (std::size_t t = 0; t < L.tilesTo[r].size(); ++t)
            forEachNode(L.nodesTo[r][t], [&](int n) {
                const double* p = &L.phi[(L.tilesTo[r][t]*npt + n)*nc];
                send_[r].insert(send_[r].end(), p, p + nc);
            });
    }
    comm_.exchange(send_, recv_);
    std::vector<const double*> got(P, nullptr);
    for (int r = 0; r < P; ++r)
    {
        if (!L.byGhostsFrom[r]) got[r] = recv_[r].data();
        else if (!L.ghostTiles[r].empty())
        {
            ghostPartialSums(L, r, recv_[r], ghostSums_[r]);
            got[r] = ghostSums_[r].data();
        }
    }
    addInRankOrder(L, got);
}

/// Rank r's partial delta on the tiles received from it (dl), formed from
/// its ghosts' residuals (got: nc a ghost) as r forms it: a run of points
/// with the same stencil nodes is sent whole or not at all (its points
/// touch the same tiles), and scattered as a run here as there (the ghosts
/// say where r's runs begin)
template <int D>
void levelApplier<D>::ghostPartialSums(const levelPlan<D>& L, int r, const std::vector<double>& got,
                                       std::vector<double>& dl)
{
    const int nc = ctrl_.nComponents, blk = levelPlan<D>::npt*nc;
    const std::size_t stride = D + nc + 1, ng = L.ghostTiles[r].size();
    const std::vector<stencil<D>>& st = L.ghostStencils[r];
    dl.assign(L.tilesFrom[r].size()*blk, 0.0);
    std::vector<double>& rr = ghostResiduals_;
    rr.assign(ng*nc, 0.0);
    for (std::size_t g = 0; g < ng; ++g)
    {
        const double* x = &L.ghostsFrom[r][g*stride];
        for (int c = 0; c < nc; ++c) rr[g*nc + c] = x[D + c] != 0 ? got[g*nc + c]*L.ghostScales[r][g] : 0.0;
    }
    if (L.separated)
    {
        for (std::size_t g = 0; g < ng; ++g)
        {
            bool on[3];
            for (int c = 0; c < nc; ++c) on[c] = L.ghostsFrom[r][g*stride + D + c] != 0;
            scatterSeparated<D>(dl.data(), nc, L.ghostTiles[r][g], st[g], &rr[g*nc],
                                ctrl_.omegaPerNode == 1 ? nullptr : on);
        }
        return;
    }
    for (std::size_t g = 0, e; g < ng; g = e)
    {
        for (e = g + 1; e < ng && L.ghostsFrom[r][e*stride + D + nc] != 0; ++e) {}
        if (e - g >= minRun) scatterRun<D>(dl.data(), nc, L.ghostTiles[r][g], &st[g], &rr[g*nc], e - g);
        else for (std::size_t j = g; j < e; ++j) scatter<D>(dl.data(), nc, L.ghostTiles[r][j], st[j], &rr[j*nc]);
    }
}

/// Sum over ranks, in rank order (every rank holding a node adds the same
/// partial sums in the same order: bitwise the same delta). This rank's own
/// sums are in place already; where a lower rank contributes too they are
/// set aside and added at this rank's turn. got: per rank, its partial sums
/// on the tiles received from it: at their nodesFrom (tiles), or at all
/// their nodes (ghosts; none: null)
template <int D>
void levelApplier<D>::addInRankOrder(levelPlan<D>& L, const std::vector<const double*>& got)
{
    constexpr int npt = levelPlan<D>::npt;
    const int nc = ctrl_.nComponents, blk = npt*nc;
    std::vector<double>& own = setAside_;
    own.resize(L.sharedWithLower.size()*blk);
    for (std::size_t t = 0; t < L.sharedWithLower.size(); ++t)
    {
        double* ph = &L.phi[L.sharedWithLower[t]*blk];
        std::copy(ph, ph + blk, &own[t*blk]);
        std::fill(ph, ph + blk, 0.0);
    }
    auto add = [&](std::int64_t id, const double* dl) {
        double* ph = &L.phi[id*blk];
        for (int j = 0; j < blk; ++j) ph[j] += dl[j];
    };
    for (int r = 0; r < comm_.size(); ++r)
    {
        if (r == comm_.rank())
            for (std::size_t t = 0; t < L.sharedWithLower.size(); ++t) add(L.sharedWithLower[t], &own[t*blk]);
        else if (L.byGhostsFrom[r])
        {
            if (got[r])
                for (std::size_t t = 0; t < L.tilesFrom[r].size(); ++t) add(L.tilesFrom[r][t], &got[r][t*blk]);
        }
        else
        {
            const double* dl = got[r];
            for (std::size_t t = 0; t < L.tilesFrom[r].size(); ++t)
                forEachNode(L.nodesFrom[r][t], [&](int n) {
                    double* ph = &L.phi[(L.tilesFrom[r][t]*npt + n)*nc];
                    for (int c = 0; c < nc; ++c) ph[c] += dl[c];
                    dl += nc;
                });
        }
    }
}

/// The chunked exchange (levelPlan::chunks): own partial sums to the
/// chunks' owners; each owner sums its chunks in rank order (as
/// addInRankOrder: the same values), divides them by omega (as
/// divideByOmega) and sends them to the tiles' readers
template <int D>
void levelApplier<D>::exchangeChunks(levelPlan<D>& L)
{
    const int P = comm_.size(), me = comm_.rank(), nc = ctrl_.nComponents, npt = levelPlan<D>::npt;
    const chunkExchange& X = L.chunks;
    auto at = [&](const nodeRun& r) { return L.phi.data() + (r.tile*npt + r.node0)*nc; };
    auto exchange = [&](const std::vector<std::vector<nodeRun>>& runs, const std::vector<std::size_t>& counts) {
        send_.resize(P);
        recv_.resize(P);
        for (int r = 0; r < P; ++r)
        {
            send_[r].clear();
            for (const nodeRun& run : runs[r]) send_[r].insert(send_[r].end(), at(run), at(run) + run.nodes*nc);
            recv_[r].resize(counts[r]);
        }
        comm_.exchange(send_, recv_);
    };
    exchange(X.partialTo, X.partialCounts);
    std::vector<double>& sum = chunkSum_;
    for (std::size_t k = 0; k < X.owned.size(); ++k)
    {
        const std::size_t n = std::size_t(X.owned[k].nodes)*nc;
        double* ph = at(X.owned[k]);
        sum.assign(n, 0.0);
        for (std::int64_t t = X.termsBegin[k]; t < X.termsBegin[k + 1]; ++t)
        {
            const chunkTerm& term = X.terms[t];
            if (term.rank == me)
            {
                for (std::size_t j = 0; j < n; ++j) sum[j] += ph[j];
                continue;
            }
            const double* v = recv_[term.rank].data() + term.offset;   // (no runs: maybe nothing received)
            for (std::int32_t q = term.runsBegin; q < term.runsEnd; ++q)
            {
                const nodeRun& run = X.termRuns[q];
                double* to = &sum[std::size_t(run.node0 - X.owned[k].node0)*nc];
                for (std::int32_t j = 0; j < run.nodes*nc; ++j) to[j] += v[j];
                v += run.nodes*nc;
            }
        }
        std::copy(sum.begin(), sum.end(), ph);
        const std::int64_t node0 = X.owned[k].tile*npt + X.owned[k].node0;
        divideByOmega(L, node0, X.owned[k].nodes, L.invOmega.data() + node0*ctrl_.omegaPerNode);
    }
    exchange(X.fullTo, X.fullCounts);
    for (int r = 0; r < P; ++r)
    {
        const double* v = recv_[r].data();
        for (const nodeRun& run : X.fullFrom[r])
        {
            std::copy(v, v + run.nodes*nc, at(run));
            v += run.nodes*nc;
        }
    }
}

/// The tree exchange (levelPlan::tree): the own partial sums at the nodes
/// summed (where omega > 0) placed among the level's values of all ranks,
/// summed over the ranks (treeSum), and every tile of the view taken from
/// the sums (0 at its other nodes)
template <int D>
void levelApplier<D>::exchangeInTree(levelPlan<D>& L)
{
    const int nc = ctrl_.nComponents, npt = levelPlan<D>::npt;
    const std::int64_t blk = npt*nc;
    std::vector<double>& sums = treeSums_;
    sums.assign(std::size_t(L.treeValues), 0.0);
    auto forNodes = [&](std::int64_t id, auto f) {
        double* v = sums.data() + L.treeStart[id];
        for (int n = 0; n < npt; ++n)
            if (L.treeNodes[id] >> n & 1)
            {
                f(L.phi.data() + id*blk + n*nc, v);
                v += nc;
            }
    };
    for (const std::int64_t id : L.ownInView)
        if (L.treeStart[id] >= 0) forNodes(id, [nc](double* ph, double* v) { std::copy(ph, ph + nc, v); });
    treeSum(comm_, sums, chunkSum_);
    std::fill(L.phi.begin(), L.phi.end(), 0.0);
    for (std::int64_t id = 0; id < std::int64_t(L.treeStart.size()); ++id)
        if (L.treeStart[id] >= 0) forNodes(id, [nc](double* ph, double* v) { std::copy(v, v + nc, ph); });
}

/// phi = delta/omega at nodes [first, first + n): s their 1/omega, one per
/// node or per value
template <int D>
void levelApplier<D>::divideByOmega(levelPlan<D>& L, std::int64_t first, std::int64_t n, const double* s) const
{
    const int nc = ctrl_.nComponents, per = ctrl_.omegaPerNode;
    double* v = L.phi.data() + first*nc;
    switch (per == 1 ? nc : 1)
    {
        case 1: scaleNodes<1>(v, s, std::size_t(n*per)); break;
        case 2: scaleNodes<2>(v, s, std::size_t(n)); break;
        default: scaleNodes<3>(v, s, std::size_t(n));
    }
}

/// Residuals at this rank's control points minus the level's values there
/// (rr: the apply's r/sum(w^2), which give them at the points alone at
/// their nodes)
template <int D>
void levelApplier<D>::subtractLevel(const levelPlan<D>& L, const std::vector<double>& rr,
                                    std::vector<double>& residuals)
{
    const std::size_t nq = ctrl_.order.size();
    const int nc = ctrl_.nComponents;
    // (the level's values first, in a pass of their own: subtracting each
    // right after its sum was stored in pieces would stall on the loads)
    levelValues_.assign(nq*nc, 0.0);
    for (std::size_t q = 0, e; q < nq; q = e)
    {
        for (e = q + 1; e < nq && stencils_[e].base == stencils_[q].base; ++e) {}
        if (L.separated || (!L.lone.empty() && L.lone[q]))
        {
            // alone at its nodes (so in no run): (r/sum(w^2)) sum(w^2)
            const double sw = stencils_[q].sumSquares();
            for (int c = 0; c < nc; ++c) levelValues_[q*nc + c] = rr[q*nc + c]*sw;
        }
        else if (e - q >= minBlockRun)
            evalRun<D>(L.phi.data(), nc, L.controlTiles[q], &stencils_[q], e - q, &levelValues_[q*nc]);
        else
            for (std::size_t j = q; j < e; ++j)
                evalStencil(L.phi.data(), nc, L.controlTiles[j], stencils_[j], &levelValues_[j*nc]);
    }
    for (std::size_t q = 0; q < nq; ++q)
    {
        const std::size_t i = ctrl_.order[q];
        for (int c = 0; c < nc; ++c) residuals[i*nc + c] -= levelValues_[q*nc + c];
    }
}

template <int D>
std::int64_t levelApplier<D>::bytes() const
{
    std::int64_t buffers = 0;
    for (const auto& v : send_) buffers += std::int64_t(v.capacity());
    for (const auto& v : recv_) buffers += std::int64_t(v.capacity());
    for (const auto& v : ghostSums_) buffers += std::int64_t(v.capacity());
    buffers += std::int64_t(ghostResiduals_.capacity());
    return std::int64_t((scaledResiduals_.capacity() + setAside_.capacity() + chunkSum_.capacity() + treeSums_.capacity() + buffers)*sizeof(double)
        + (stencils_.capacity() + cubedStencils_.capacity())*sizeof(stencil<D>));
}

template <int D>
void storeDeferredCoefficients(const levelPlan<D>& L, const controlPoints<D>& ctrl)
{
    // (the lattice's value does not change: these nodes were written by no
    // other point, and are read by nothing that ran since the fit)
    if (L.allCoefficientsStored) return;
    const int nc = ctrl.nComponents;
    std::size_t pos = 0;
    ctrl.forEachStencil(L.scale, [&](std::size_t i, const stencil<D>& st) {
        bool on[3];
        if (!L.readEveryFit[pos])
            scatterSeparated<D>(L.phi.data(), nc, L.controlTiles[pos], st, &L.scaledResiduals[pos*nc],
                                ctrl.constrained(i, on));
        ++pos;
    });
    L.allCoefficientsStored = true;
}

template class levelApplier<2>;
template class levelApplier<3>;
template void storeDeferredCoefficients<2>(const levelPlan<2>&, const controlPoints<2>&);
template void storeDeferredCoefficients<3>(const levelPlan<3>&, const controlPoints<3>&);

} // namespace mba
