// The sweep of the flat lattice over the evaluation points (its kernels),
// then the lattice's rebuild after a fit and the evaluation.
#include "flatEvaluator.hpp"
#include "plainLattice.hpp"
#include "subdivision.hpp"

#include <algorithm>
#include <cmath>

namespace mba {

double flatNodeBudget(std::size_t nEval)
{
    const double n = double(nEval);
    return std::max({4096.0, std::min(n, 65536.0), n/8});
}

namespace {

/// Asks the cache for the rows of the flat lattice's stencil at u (level-local
/// coordinates): the lattice is too large for the nearer caches, and rows
/// along the first directions lie planes apart. last: the stencil asked for
/// before, whose rows are not asked for again (where the stencil moved one
/// node along the first direction, only its new plane of rows is)
inline __attribute__((always_inline)) void prefetchRows(const double* G, const indexBox<3>& b, int nc,
                                                        const point<3>& u, index<3>& last)
{
    const index<3> base{{std::int64_t(u[0]), std::int64_t(u[1]), std::int64_t(u[2])}};  // as stencil's
    if (base == last) return;
    const int a0 = base[0] == last[0] + 1 && base[1] == last[1] && base[2] == last[2] ? 3 : 0;
    last = base;
    const std::int64_t n1 = b.hi[1] - b.lo[1] + 1, n2 = b.hi[2] - b.lo[2] + 1;
    const double* p0 = flatNode<3>(G, b, base, nc);
    for (int a = a0; a < 4; ++a)
        for (int c = 0; c < 4; ++c)
        {
            const double* p = p0 + (a*n1 + c)*n2*nc;
            __builtin_prefetch(p);              // a row's first and last value:
            __builtin_prefetch(p + 4*nc - 1);   // the cache lines it spans
        }
}
/// (2D lattices are small enough)
inline void prefetchRows(const double*, const indexBox<2>&, int, const point<2>&, index<2>&) {}

/// Points ahead whose stencil rows flatSweep asks the cache for (about the
/// time a point takes against the latency of memory)
constexpr std::size_t prefetchDistance = 4;

/// The flat lattice's values at the points with level-0 local coordinates
/// u0[0..n), to out (NC a point: a fixed size, so that a point's values go
/// from registers to out, not through a call to copy them)
template <int D, int NC, int W>
inline __attribute__((always_inline)) void flatSweepAs(const double* G, const indexBox<D>& b, double sf,
                                                       const point<D>* u0, std::size_t n, double* out)
{
    index<D> last;
    last.fill(-2);      // (no stencil's)
    for (std::size_t q = 0; q < n; ++q)
    {
        if (q + prefetchDistance < n) prefetchRows(G, b, NC, scaled<D>(u0[q + prefetchDistance], sf), last);
        double acc[NC] = {};
        flatStencil<NC, W>(G, b, stencil<D>(scaled<D>(u0[q], sf).data()), acc);
        for (int c = 0; c < NC; ++c) out[q*NC + c] = acc[c];
    }
}

/// The same for nc values a point
template <int D, int W>
inline __attribute__((always_inline)) void flatSweep(const double* G, const indexBox<D>& b, int nc, double sf,
                                                     const point<D>* u0, std::size_t n, double* out)
{
    switch (nc)
    {
        case 1: flatSweepAs<D, 1, W>(G, b, sf, u0, n, out); break;
        case 2: flatSweepAs<D, 2, W>(G, b, sf, u0, n, out); break;
        default: flatSweepAs<D, 3, W>(G, b, sf, u0, n, out);
    }
}

#ifdef MBA_WIDE_VECTORS
/// The same compiled for AVX2 with FMA, in vectors of four doubles
template <int D>
MBA_WIDE_TARGET void flatSweepWide(const double* G, const indexBox<D>& b, int nc, double sf, const point<D>* u0,
                                   std::size_t n, double* out)
{
    flatSweep<D, 4>(G, b, nc, sf, u0, n, out);
}

/// The same in 3D, the stencils' weights four points at a time (one point a
/// lane; past the end the last point again, so that every point's weights
/// come from the same arithmetic): a point's sweep is then its 48 fused adds
/// and little else
template <int NC>
MBA_WIDE_TARGET void flatSweepBlocks(const double* G, const indexBox<3>& b, double sf, const point<3>* u0,
                                     std::size_t n, double* out)
{
    typedef vec<4>::type v4d;
    typedef int v4i __attribute__((vector_size(16)));
    const std::int64_t n1 = b.hi[1] - b.lo[1] + 1, n2 = b.hi[2] - b.lo[2] + 1;
    index<3> last;
    last.fill(-2);      // (no stencil's)
    alignas(32) double wxy[16][4], wz[4][4];
    alignas(16) int base[3][4];
    for (std::size_t q0 = 0; q0 < n; q0 += 4)
    {
        const std::size_t m = std::min<std::size_t>(4, n - q0);
        v4d w[3][4];
        for (int d = 0; d < 3; ++d)
        {
            v4d u;
            for (int j = 0; j < 4; ++j) u[j] = u0[q0 + std::min<std::size_t>(j, m - 1)][d];
            u *= sf;
            // the cell by truncation, as stencil's
            const v4i i = __builtin_convertvector(u, v4i);
            *reinterpret_cast<v4i*>(base[d]) = i;
            cubicBasis<v4d>(u - __builtin_convertvector(i, v4d), w[d]);
        }
        for (int a = 0; a < 4; ++a)
        {
            for (int c = 0; c < 4; ++c) *reinterpret_cast<v4d*>(wxy[a*4 + c]) = w[0][a]*w[1][c];
            *reinterpret_cast<v4d*>(wz[a]) = w[2][a];
        }
        for (std::size_t j = 0; j < m; ++j)
        {
            const std::size_t q = q0 + j;
            if (q + prefetchDistance < n) prefetchRows(G, b, NC, scaled<3>(u0[q + prefetchDistance], sf), last);
            const double* p0 = flatNode<3>(G, b, index<3>{{base[0][j], base[1][j], base[2][j]}}, NC);
            const double wl[4] = {wz[0][j], wz[1][j], wz[2][j], wz[3][j]};
            double acc[NC] = {};
            flatRows<NC, 4>(p0, n1, n2, [&](int a, int c) { return wxy[a*4 + c][j]; }, wl, acc);
            for (int c = 0; c < NC; ++c) out[q*NC + c] = acc[c];
        }
    }
}

template <>
void flatSweepWide<3>(const double* G, const indexBox<3>& b, int nc, double sf, const point<3>* u0,
                      std::size_t n, double* out)
{
    switch (nc)
    {
        case 1: flatSweepBlocks<1>(G, b, sf, u0, n, out); break;
        case 2: flatSweepBlocks<2>(G, b, sf, u0, n, out); break;
        default: flatSweepBlocks<3>(G, b, sf, u0, n, out);
    }
}
#endif

} // namespace

/// The level-k nodes that the stencils of points in the evaluation points'
/// level-0 box touch
template <int D>
indexBox<D> flatEvaluator<D>::evalNodeBox(int k) const
{
    const double s = std::ldexp(1.0, k);
    indexBox<D> b;
    for (int d = 0; d < D; ++d)
    {
        b.lo[d] = std::int64_t(std::floor(eval_.lo0[d]*s));
        b.hi[d] = std::int64_t(std::floor(eval_.hi0[d]*s)) + 3;
    }
    return b;
}

template <int D>
void flatEvaluator<D>::update(std::deque<levelPlan<D>>& levels, int nLevels, const affineFit<D>& affine,
                              const trendLattice<D>& trend, int nRanks)
{
    flatLevel_ = -1;
    if (eval_.size() == 0) return;
    const int m = chooseFlatLevel(nLevels, trend);
    if (m < 0) return;
    foldLevels(levels, nLevels, m, affine, trend);
    flatLevel_ = m;
    // Which finer levels have coefficients at each evaluation point: the
    // same as long as the levels and flatLevel_ are
    const std::pair<int, int> key(int(levels.size()), flatLevel_);
    if (key == finerLevelsFoundFor_) return;
    std::vector<std::vector<std::uint8_t>> read = findFinerLevels(levels);
    finerLevelsFoundFor_ = key;
    markReadEveryFit(levels, read, nRanks);
}

/// The finest of the first nLevels levels whose node box has at most
/// flatNodeBudget() nodes, and at least the trend's level (a trend has no
/// levels of its own to be added point by point); -1: none
template <int D>
int flatEvaluator<D>::chooseFlatLevel(int nLevels, const trendLattice<D>& trend) const
{
    const double budget = flatNodeBudget(eval_.size());
    int m = -1;
    while (m + 1 < nLevels && boxNodes<D>(evalNodeBox(m + 1)) <= budget) ++m;
    return std::max(m, trend.level);
}

/// flatPhi_: the affine approximation, the trend and levels 0..m (those of
/// the first nLevels), refined to level m on its node box, summed
template <int D>
void flatEvaluator<D>::foldLevels(const std::deque<levelPlan<D>>& levels, int nLevels, int m,
                                  const affineFit<D>& affine, const trendLattice<D>& trend)
{
    indexBox<D> gb;
    for (int k = 0; k <= m; ++k)
    {
        const indexBox<D> fb = evalNodeBox(k);
        if (k == 0) addAffine(fb, affine);
        else refine<D>(flatPhi_, gb, fb, nc_, refineScratch_);
        gb = fb;
        if (k == trend.level) addTrend(gb, trend);
        if (k < nLevels) addLevelInBox(levels[k], gb);
    }
    flatBox_ = gb;
}

/// flatPhi_ (on the node box b of the trend's level) += the trend's coefficients
template <int D>
void flatEvaluator<D>::addTrend(const indexBox<D>& b, const trendLattice<D>& trend)
{
    forEachIndex<D>(b, [&](const index<D>& j) {
        const double* p = &trend.phi[std::size_t(boxIndex<D>(trend.box, j))*nc_];
        double* o = &flatPhi_[boxIndex<D>(b, j)*nc_];
        for (int c = 0; c < nc_; ++c) o[c] += p[c];
    });
}

/// flatPhi_ on the level-0 node box b: the affine approximation. Cubic
/// B-splines reproduce linear functions, node j (u = j - 1 in level units)
/// taking the function's value there; refined with the levels (exactly)
template <int D>
void flatEvaluator<D>::addAffine(const indexBox<D>& b, const affineFit<D>& affine)
{
    const std::size_t n = std::size_t(boxNodes<D>(b))*nc_;
    holdAtLeast(flatPhi_, n);
    std::fill_n(flatPhi_.begin(), n, 0.0);
    forEachIndex<D>(b, [&](const index<D>& j) {
        double x[D];
        for (int d = 0; d < D; ++d) x[d] = dom_.lo[d] + double(j[d] - 1)*dom_.h0;
        affine.addTo(x, &flatPhi_[boxIndex<D>(b, j)*nc_]);
    });
}

/// flatPhi_ (on the node box b of L's level) += L's coefficients in the
/// box: those stored, and the lone points' (w r/sum(w^2) at their nodes)
template <int D>
void flatEvaluator<D>::addLevelInBox(const levelPlan<D>& L, const indexBox<D>& b)
{
    constexpr int npt = levelPlan<D>::npt;
    for (std::size_t j = 0; j < L.lonePoints.size(); ++j)
    {
        const stencil<D> st = ctrl_.stencilAt(L.lonePoints[j], L.scale);
        indexBox<D> nb;
        for (int d = 0; d < D; ++d) { nb.lo[d] = st.base[d]; nb.hi[d] = st.base[d] + 3; }
        const double* rr = &L.loneResiduals[j*nc_];
        forEachIndex<D>(nb, [&](const index<D>& n) {
            if (!b.contains(n)) return;
            double w = 1;
            for (int d = 0; d < D; ++d) w *= st.w[d][n[d] - st.base[d]];
            double* o = &flatPhi_[boxIndex<D>(b, n)*nc_];
            for (int c = 0; c < nc_; ++c) o[c] += w*rr[c];
        });
    }
    for (std::int64_t id = 0; id < L.storedTiles; ++id)
    {
        const index<D> t = L.view.coord(L.view.keyOf(id));
        indexBox<D> tb, nb;     // the tile's nodes; those in the box
        bool inside = true;
        for (int d = 0; d < D; ++d)
        {
            tb.lo[d] = t[d]*tileEdge;
            tb.hi[d] = tb.lo[d] + tileEdge - 1;
            nb.lo[d] = std::max(tb.lo[d], b.lo[d]);
            nb.hi[d] = std::min(tb.hi[d], b.hi[d]);
            inside = inside && nb.lo[d] <= nb.hi[d];
        }
        if (!inside) continue;
        forEachIndex<D>(nb, [&](const index<D>& j) {
            const double* p = &L.phi[(id*npt + boxIndex<D>(tb, j))*nc_];
            double* o = &flatPhi_[boxIndex<D>(b, j)*nc_];
            for (int c = 0; c < nc_; ++c) o[c] += p[c];
        });
    }
}

/// Which levels above flatLevel_ have coefficients at each evaluation point:
/// levels whose lattice has a node with omega > 0 and a non-zero weight in
/// the point's stencil. Where a level has no tile at the stencil, no finer
/// level has one (their nodes lie within the stencils of the same control
/// points). With them the stencil's stored tiles (-1 for the others) and
/// the lone points whose nodes it meets (forEachLoneOverlap). Returns, for
/// separated levels, the view tiles that this reads.
template <int D>
std::vector<std::vector<std::uint8_t>> flatEvaluator<D>::findFinerLevels(const std::deque<levelPlan<D>>& levels)
{
    int nPlanned = 0;   // (up to a level that none reads)
    while (nPlanned < int(levels.size()) && levels[nPlanned].read) ++nPlanned;
    precondition(nPlanned - flatLevel_ - 1 <= 32, "mba: more than 32 levels above the flat lattice");
    finerLevelPoints_.clear();
    finerLevelTiles_.clear();
    finerLonePairs_.clear();
    finerEntries_.clear();
    std::vector<std::vector<std::uint8_t>> read(levels.size());
    for (int k = flatLevel_ + 1; k < nPlanned; ++k)
        if (levels[k].separated) read[k].assign(levels[k].view.size(), 0);
    stencilTiles<D> tid;
    std::vector<std::uint32_t> scratch;
    for (std::size_t q = 0; q < eval_.size(); ++q)
    {
        std::uint32_t m = 0;
        for (int k = flatLevel_ + 1; k < nPlanned; ++k)
        {
            const levelPlan<D>& L = levels[k];
            const stencil<D> st = levelStencil<D>(eval_.u0[q], L.scale);
            double w[3];
            if (!coefficientWeights(L, st, tid, w)) break;
            if (!(w[0] + w[1] + w[2] > 0)) continue;
            m |= std::uint32_t(1) << (k - flatLevel_ - 1);
            if (!read[k].empty()) for (const std::int32_t id : tid) if (id >= 0) read[k][id] = 1;
            const std::size_t first = finerLonePairs_.size();
            forEachLoneOverlap(L, ctrl_, st, tid, scratch,
                               [&](std::uint32_t j, double K) { finerLonePairs_.push_back({K, j}); });
            const std::size_t nPairs = finerLonePairs_.size() - first;
            precondition(nPairs < storedEntry, "mba: a point meets too many lone points");
            bool stored = false;
            for (std::int32_t& id : tid)
            {
                if (id >= L.storedTiles) id = -1;
                stored = stored || id >= 0;
            }
            if (stored) finerLevelTiles_.push_back(tid);
            finerEntries_.push_back(std::uint16_t(nPairs | (stored ? storedEntry : 0)));
        }
        if (m) finerLevelPoints_.emplace_back(std::uint32_t(q), m);
    }
    finerLevelPoints_.shrink_to_fit();
    finerLevelTiles_.shrink_to_fit();
    finerLonePairs_.shrink_to_fit();
    finerEntries_.shrink_to_fit();
    return read;
}

/// Whether a node of positive weight in the stencil st at level L (of an
/// evaluation point, L.scale: levelStencil) has coefficients, per omega
/// value (per component, or w[0] for all when a node holds one omega):
/// w[j] is 1 where one has, else 0. False when no tile of L's view meets the
/// stencil (nor does any finer level's: their nodes lie within the stencils
/// of the same control points).
template <int D>
bool flatEvaluator<D>::coefficientWeights(const levelPlan<D>& L, const stencil<D>& st, stencilTiles<D>& tid,
                                          double w[3]) const
{
    w[0] = w[1] = w[2] = 0;
    if (!findTiles(L.view, st, tid)) return false;
    const int per = ctrl_.omegaPerNode;
    const indexBox<D> tb = st.tiles();
    for (int c = 0; c < (1 << D); ++c)
    {
        if (tid[c] < 0) continue;
        const std::uint64_t nodes = st.nodesIn(stencilTile<D>(tb, c), true);
        for (int j = 0; j < per; ++j)
            if (L.coefficientNodes[std::size_t(tid[c])*per + j] & nodes) w[j] = 1;
    }
    return true;
}

template <int D>
bool flatEvaluator<D>::reads(const levelPlan<D>& L) const
{
    stencilTiles<D> tid;
    double w[3];
    for (std::size_t q = 0; q < eval_.size(); ++q)
    {
        if (!coefficientWeights(L, levelStencil<D>(eval_.u0[q], L.scale), tid, w)) continue;
        const std::size_t i = eval_.at(q);
        for (int c = 0; c < nc_; ++c)
            if (w[ctrl_.omegaPerNode == 1 ? 0 : c] > 0 && eval_.reads(i, c)) return true;
    }
    return false;
}

/// Separated levels: the points whose phi is stored in every fit are those
/// with a tile read by the evaluation (read) or sent as a tile to another
/// rank; all of them where the level is folded into the flat lattice
template <int D>
void flatEvaluator<D>::markReadEveryFit(std::deque<levelPlan<D>>& levels,
                                        std::vector<std::vector<std::uint8_t>>& read, int nRanks) const
{
    for (int k = 0; k < int(levels.size()); ++k)
    {
        levelPlan<D>& L = levels[k];
        if (!L.separated) continue;
        if (k <= flatLevel_)
        {
            std::fill(L.readEveryFit.begin(), L.readEveryFit.end(), 1);
            continue;
        }
        for (int r = 0; r < nRanks && nRanks > 1; ++r)
            if (!L.byGhostsTo[r])
                for (const std::int64_t id : L.tilesTo[r]) read[k][id] = 1;
        for (std::size_t q = 0; q < L.readEveryFit.size(); ++q)
        {
            L.readEveryFit[q] = 0;
            for (const std::int32_t id : L.controlTiles[q]) if (id >= 0 && read[k][id]) L.readEveryFit[q] = 1;
        }
    }
}

template <int D>
void flatEvaluator<D>::evaluate(const std::deque<levelPlan<D>>& levels, int nLevels, std::vector<double>& out) const
{
    // The flat lattice point after point in the sweep's order, then the
    // finer levels at the points that have tiles there. In the points' own
    // order the results are written in place; in spatial order into
    // sweptValues_, from which the points' own order then gathers them (the
    // reads and writes of points and results stay in sequence)
    const std::size_t n = eval_.size();
    const bool own = eval_.order.empty();
    if (out.capacity() < n*nc_)
    {
        // (a new array: on huge pages where the kernel takes the advice)
        std::vector<double>().swap(out);
        out.reserve(n*nc_);
        adviseHugePages(out.data(), n*nc_*sizeof(double));
    }
    out.resize(n*nc_);     // (every value is written below)
    if (!own) sweptValues_.resize(n*nc_);
    double* dst = own ? out.data() : sweptValues_.data();
    const double sf = std::ldexp(1.0, flatLevel_);
#ifdef MBA_WIDE_VECTORS
    if (wideVectors())
        flatSweepWide<D>(flatPhi_.data(), flatBox_, nc_, sf, eval_.u0.data(), n, dst);
    else
#endif
        flatSweep<D, 2>(flatPhi_.data(), flatBox_, nc_, sf, eval_.u0.data(), n, dst);
    addFinerLevels(levels, nLevels, dst);
    for (std::size_t i = 0; i < n && !own; ++i)
    {
        const double* v = &sweptValues_[std::size_t(eval_.position[i])*nc_];
        for (int c = 0; c < nc_; ++c) out[i*nc_ + c] = v[c];
    }
}

/// + the finer levels (of the first nLevels), in a pass of their own over
/// the points that have them (values: in the sweep's order)
template <int D>
void flatEvaluator<D>::addFinerLevels(const std::deque<levelPlan<D>>& levels, int nLevels, double* values) const
{
    const stencilTiles<D>* tiles = finerLevelTiles_.data();
    const std::uint16_t* entry = finerEntries_.data();
    const lonePair* pair = finerLonePairs_.data();
    for (const auto& qm : finerLevelPoints_)
    {
        const std::size_t q = qm.first;
        double* v = &values[q*nc_];
        int k = flatLevel_ + 1;
        for (std::uint32_t m = qm.second; m; m >>= 1, ++k)
        {
            if (!(m & 1)) continue;
            const bool stored = *entry & storedEntry;
            const lonePair* end = pair + (*entry++ & ~storedEntry);
            if (k < nLevels)
            {
                const levelPlan<D>& L = levels[k];
                if (stored) evalStencil(L.phi.data(), nc_, *tiles, levelStencil<D>(eval_.u0[q], L.scale), v);
                for (const lonePair* p = pair; p != end; ++p)
                    for (int c = 0; c < nc_; ++c) v[c] += p->K*L.loneResiduals[p->j*nc_ + c];
            }
            tiles += stored;
            pair = end;
        }
    }
}

template <int D>
std::int64_t flatEvaluator<D>::bytes() const
{
    return std::int64_t((flatPhi_.capacity() + refineScratch_.capacity() + sweptValues_.capacity())*sizeof(double)
        + finerLevelPoints_.capacity()*sizeof(finerLevelPoints_[0])
        + finerLevelTiles_.capacity()*sizeof(stencilTiles<D>)
        + finerLonePairs_.capacity()*sizeof(lonePair) + finerEntries_.capacity()*sizeof(std::uint16_t));
}

template class flatEvaluator<2>;
template class flatEvaluator<3>;

} // namespace mba
