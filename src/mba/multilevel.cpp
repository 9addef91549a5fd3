#include "multilevel.hpp"
#include "buckets.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace mba {

// The definition C++14 needs where the key is bound to a reference
constexpr std::uint64_t hashMap::emptyKey;

void params::validate() const
{
    precondition(std::isfinite(tolerance) && tolerance >= 0,
        "mba: tolerance must be a finite number >= 0, got " + std::to_string(tolerance));
    precondition(maxLevels >= 1 && maxLevels <= 30,
        "mba: maxLevels must be in [1, 30], got " + std::to_string(maxLevels));
    precondition(initialGrid >= 1 && initialGrid <= (1 << 20),
        "mba: initialGrid must be in [1, 2^20], got " + std::to_string(initialGrid));
    precondition(std::isfinite(padding) && padding > 0 && padding <= 1,
        "mba: padding must be in (0, 1], got " + std::to_string(padding));
    precondition(bucketTiles >= 1, "mba: bucketTiles must be >= 1, got " + std::to_string(bucketTiles));
}

namespace {

double now()
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// Runs f; an std::invalid_argument on any rank becomes the same error on all
template <class F>
void collectively(const communicator& comm, F&& f)
{
    std::string err;
    try { f(); }
    catch (const std::invalid_argument& e) { err = e.what(); }
    comm.check(err.empty(), err);
}

template <int D>
point<D> scaled(point<D> u, double s)
{
    for (auto& x : u) x *= s;
    return u;
}

} // namespace

template <int D>
struct multilevel<D>::level
{
    static constexpr int npt = tileLayout<D>::nodesPerTile;
    int k = 0;
    double scale = 1;               ///< 2^k: u_k = u_0*scale
    tileLayout<D> own, view;
    bool ownIsView = false;         ///< serial, sparse: own tiles are the view (own left empty)
    /// No two control points (of any rank) share a node of their stencils
    /// (fine levels, where the points are farther apart than a stencil): a
    /// point's nodes then take phi = w r/sum(w^2) from it alone, and its
    /// residual after the level is r - (r/sum(w^2)) sum(w^2), 0 but for
    /// rounding. Per fit the lattice is neither cleared (but for the tiles
    /// other ranks' sums arrive in) nor scaled by 1/omega nor swept, and phi
    /// is stored only at the points whose tiles are read in every fit
    /// (readEveryFit: by this rank's evaluation stencils, by other ranks,
    /// or for the flat lattice); the others' phi is stored from rr when
    /// evaluateControl or evaluate(x) asks for the whole lattice (complete).
    bool separated = false;
    std::vector<std::uint8_t> readEveryFit; ///< per own point in ctrlOrder_
    std::vector<double> rr;                 ///< per own point x component: r/sum(w^2) of the last fit
    bool complete = true;                   ///< every point's phi stored since the last fit
    hugeVector<double> phi, invOmega; ///< view data: coefficients, 1/omega (0 where omega is)
    std::vector<std::vector<std::int64_t>> sendTiles, recvTiles; ///< view tile ids per rank (own ones / received ones)
    /// Own tiles (view ids) that a lower rank also contributes to: this
    /// rank's partial sums there are set aside and added in rank order
    std::vector<std::int64_t> lowShared;
    /// The tiles of the control points' stencils (in ctrlOrder_) in the view
    std::vector<stencilTiles<D>> ctrlView;
    /// Ghosts: where a rank's control points near another rank's stencils cost
    /// less to send than the tiles they touch (fine levels), the owner sends
    /// their residuals and the receiver computes the owner's partial delta
    /// from them, bitwise as the owner would (same points, same order).
    /// ghostSend[r]: this rank's points whose residuals go to r (ghost mode to r);
    /// ghostX[r]: r's ghost points, D coordinates + nc mask flags each;
    /// ghostTiles[r]: their stencils' tiles, as positions in recvTiles[r]
    std::vector<std::vector<std::uint32_t>> ghostSend;
    bool ghosts = false;            ///< this rank sends or receives ghosts at this level
    std::vector<std::vector<double>> ghostX;
    std::vector<std::vector<stencilTiles<D>>> ghostTiles;
    levelStats stats;

    const tileLayout<D>& ownTiles() const { return ownIsView ? view : own; }
};

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

/// A point of a separated level (level::separated): the only one at its
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

/// Node i of a plain lattice over the nodes of box b (the last direction
/// fastest, nc values a node)
template <int D>
inline const double* flatNode(const double* G, const indexBox<D>& b, const index<D>& i, int nc)
{
    return G + boxIndex<D>(b, i)*nc;
}

/// Adds to out[0..NC) the value at a stencil of a plain 3D lattice whose
/// first node is p0 (n1, n2: the box's nodes along the second and last
/// directions; the last direction fastest, NC values a node): the 4 nodes
/// along the last direction are contiguous, so the 16 rows, weighted by
/// rowW(a, c) (the product of the first two directions' weights), are summed
/// first, as vectors of W doubles, into two accumulators (alternate rows:
/// two independent add chains), and the sum then weighted by wLast
template <int NC, int W, class RowW>
inline __attribute__((always_inline)) void flatRows(const double* p0, std::int64_t n1, std::int64_t n2,
                                                    RowW&& rowW, const double* wLast, double* out)
{
    detail::vrow<4*NC, W> r[2] = {};
    for (int a = 0; a < 4; ++a)
        for (int c = 0; c < 4; ++c) detail::axpy<4*NC, W>(r[c & 1], rowW(a, c), p0 + (a*n1 + c)*n2*NC);
    detail::add(r[0], r[1]);
    detail::addRowSum<NC, W>(r[0], wLast, out);
}

/// Adds the value at a stencil of a plain lattice (nodes of box b, the last
/// direction fastest, NC values per node), as flatRows
template <int NC, int W>
inline __attribute__((always_inline)) void flatStencil(const double* G, const indexBox<3>& b,
                                                       const stencil<3>& st, double* out)
{
    flatRows<NC, W>(flatNode<3>(G, b, st.base, NC), b.hi[1] - b.lo[1] + 1, b.hi[2] - b.lo[2] + 1,
                    [&](int a, int c) { return st.w[0][a]*st.w[1][c]; }, st.w[2], out);
}

template <int NC, int W>
inline __attribute__((always_inline)) void flatStencil(const double* G, const indexBox<2>& b,
                                                       const stencil<2>& st, double* out)
{
    const std::int64_t n1 = b.hi[1] - b.lo[1] + 1;
    const double* p0 = flatNode<2>(G, b, st.base, NC);
    detail::vrow<4*NC, W> r[2] = {};
    for (int a = 0; a < 4; ++a) detail::axpy<4*NC, W>(r[a & 1], st.w[0][a], p0 + a*n1*NC);
    detail::add(r[0], r[1]);
    detail::addRowSum<NC, W>(r[0], st.w[1], out);
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

/// Morton code of a point's level-0 local coordinates on a 2^(63/D) grid
template <int D>
std::uint64_t morton(const point<D>& u, const domain<D>& dom)
{
    constexpr int bits = 63/D;
    std::uint64_t code = 0;
    std::uint64_t q[D];
    for (int d = 0; d < D; ++d)
    {
        const double f = u[d]/double(dom.n0[d]);
        q[d] = std::uint64_t(std::min(std::max(f, 0.0), 1.0 - 1e-16)*double(std::uint64_t(1) << bits));
    }
    for (int b = bits - 1; b >= 0; --b)
        for (int d = 0; d < D; ++d) code = (code << 1) | ((q[d] >> b) & 1u);
    return code;
}

/// Indices of the selected points in Morton order (locality for the lattices)
template <int D>
std::vector<std::uint32_t> spatialOrder(pointsView<D> x, const domain<D>& dom, const std::vector<std::uint8_t>* select)
{
    std::vector<std::pair<std::uint64_t, std::uint32_t>> key;
    key.reserve(x.size);
    for (std::size_t i = 0; i < x.size; ++i)
        if (!select || (*select)[i]) key.emplace_back(morton<D>(dom.local0(x[i]), dom), std::uint32_t(i));
    std::sort(key.begin(), key.end());
    std::vector<std::uint32_t> order(key.size());
    for (std::size_t i = 0; i < key.size(); ++i) order[i] = key[i].second;
    return order;
}

} // namespace

template <int D>
multilevel<D>::multilevel(const communicator& comm, const params& p, int nComponents,
                          pointsView<D> control, std::vector<std::uint8_t> mask,
                          pointsView<D> evaluation, const box<D>* bounds)
:
    comm_(comm), p_(p), nc_(nComponents), nw_(1), ctrl_(control), eval_(evaluation), mask_(std::move(mask))
{
    collectively(comm_, [&] {
        p_.validate();
        precondition(nc_ >= 1 && nc_ <= 3, "mba: 1 to 3 value components, got " + std::to_string(nc_));
        precondition(mask_.empty() || mask_.size() == ctrl_.size*nc_,
            "mba: the mask has " + std::to_string(mask_.size()) + " entries, expected "
            + std::to_string(ctrl_.size*nc_) + " (control points x components)");
        for (std::size_t i = 0; i < ctrl_.size; ++i)
            for (int d = 0; d < D; ++d)
                if (!std::isfinite(ctrl_[i][d]))
                    precondition(false, "mba: control point " + std::to_string(i) + " has a non-finite coordinate");
        for (std::size_t i = 0; i < eval_.size; ++i)
            for (int d = 0; d < D; ++d)
                if (!std::isfinite(eval_[i][d]))
                    precondition(false, "mba: evaluation point " + std::to_string(i) + " has a non-finite coordinate");
    });

    // Which points constrain anything; whether masks differ between components
    active_.assign(ctrl_.size, 1);
    bool mixed = false;
    if (!mask_.empty())
    {
        for (std::size_t i = 0; i < ctrl_.size; ++i)
        {
            int on = 0;
            for (int c = 0; c < nc_; ++c) on += mask_[i*nc_ + c] != 0;
            active_[i] = on > 0;
            mixed = mixed || (on > 0 && on < nc_);
        }
    }
    nw_ = comm_.max(mixed ? 1.0 : 0.0) > 0 ? nc_ : 1;
    std::int64_t nActive = 0;
    for (auto a : active_) nActive += a;
    nCtrlGlobal_ = comm_.sum(nActive);

    // Domain: global bounding box, padded
    box<D> b = box<D>::empty();
    for (std::size_t i = 0; i < ctrl_.size; ++i) if (active_[i]) b.add(ctrl_[i]);
    for (std::size_t i = 0; i < eval_.size; ++i) b.add(eval_[i]);
    std::vector<double> mm(2*D);
    for (int d = 0; d < D; ++d) { mm[d] = b.lo[d]; mm[D + d] = -b.hi[d]; }
    for (const auto& v : comm_.allGather(mm))
        for (int d = 0; d < D; ++d) { b.lo[d] = std::min(b.lo[d], v[d]); b.hi[d] = std::max(b.hi[d], -v[D + d]); }
    if (bounds)
    {
        collectively(comm_, [&] {
            for (int d = 0; d < D; ++d)
                precondition(b.isEmpty() || (bounds->lo[d] <= b.lo[d] && b.hi[d] <= bounds->hi[d]),
                    "mba: the given bounds do not contain all points");
        });
        b = *bounds;
    }
    collectively(comm_, [&] { dom_ = domain<D>::fromBox(b, p_.initialGrid, p_.padding); });
    precondition(ctrl_.size < (std::size_t(1) << 32) && eval_.size < (std::size_t(1) << 32),
        "mba: at most 2^32 points per rank");
    ctrlOrder_ = spatialOrder<D>(ctrl_, dom_, &active_);
    for (const std::uint32_t i : ctrlOrder_) ctrlU0_.push_back(dom_.local0(ctrl_[i]));
    evalOrder_ = spatialOrder<D>(eval_, dom_, nullptr);
    {
        // Mesh points mostly come numbered with locality already: when their
        // own order is about as short a path as the curve's, it serves, and
        // the results are then written in sequence
        auto path = [&](auto at) {
            double s = 0;
            for (std::size_t q = 1; q < eval_.size; ++q)
                for (int d = 0; d < D; ++d) s += std::abs(eval_[at(q)][d] - eval_[at(q - 1)][d]);
            return s;
        };
        if (path([](std::size_t q) { return q; }) <= 1.5*path([&](std::size_t q) { return evalOrder_[q]; }))
            evalOrder_ = std::vector<std::uint32_t>();
        else
        {
            evalPos_.resize(eval_.size);
            for (std::size_t q = 0; q < eval_.size; ++q) evalPos_[evalOrder_[q]] = std::uint32_t(q);
        }
    }
    evalLo0_.fill(HUGE_VAL);
    evalHi0_.fill(-HUGE_VAL);
    evalU0_.reserve(eval_.size);
    for (std::size_t q = 0; q < eval_.size; ++q)
    {
        const point<D> u = dom_.local0(eval_[evalAt(q)]);
        evalU0_.push_back(u);
        for (int d = 0; d < D; ++d) { evalLo0_[d] = std::min(evalLo0_[d], u[d]); evalHi0_[d] = std::max(evalHi0_[d], u[d]); }
    }

    if (p_.affine)
    {
        point<D> centre;
        double ext = 0;
        for (int d = 0; d < D; ++d)
        {
            centre[d] = dom_.lo[d] + 0.5*dom_.n0[d]*dom_.h0;
            ext = std::max(ext, dom_.n0[d]*dom_.h0);
        }
        affine_ = affineFit<D>(comm_, nc_, ctrl_, mask_, centre, 0.5*ext);
    }

    // Clusters of this rank's query points: which remote buckets it needs
    if (comm_.size() > 1)
    {
        std::vector<const double*> q;
        for (std::size_t i = 0; i < ctrl_.size; ++i) if (active_[i]) q.push_back(ctrl_[i]);
        for (std::size_t i = 0; i < eval_.size; ++i) q.push_back(eval_[i]);
        const std::int64_t leaf = std::max<std::int64_t>(64, std::int64_t(q.size())/512);
        const auto groups = bisect<D>(std::int64_t(q.size()), [&](std::int64_t i) {
            point<D> x;
            for (int d = 0; d < D; ++d) x[d] = q[i][d];
            return x;
        }, leaf);
        for (const auto& g : groups)
        {
            box<D> qb = box<D>::empty();
            std::vector<const double*> members;
            for (auto i : g) { qb.add(q[i]); members.push_back(q[i]); }
            queryBoxes_.push_back(qb);
            queryGroups_.push_back(std::move(members));
        }
    }
    residual_.assign(ctrl_.size*nc_, 0.0);
}

template <int D>
multilevel<D>::~multilevel() = default;

template <int D>
inline __attribute__((always_inline)) stencil<D> multilevel<D>::ctrlStencil(const level& L, std::size_t q) const
{
    return stencil<D>(scaled<D>(ctrlU0_[q], L.scale).data());
}

template <int D>
template <class F>
void multilevel<D>::forOwnStencils(const level& L, F&& f) const
{
    for (std::size_t q = 0; q < ctrlOrder_.size(); ++q) f(std::size_t(ctrlOrder_[q]), ctrlStencil(L, q));
}

template <int D>
void multilevel<D>::buildLevel(int k)
{
    const double t0 = now();
    constexpr int npt = level::npt;
    const int P = comm_.size(), me = comm_.rank();
    std::unique_ptr<level> Lp(new level);
    level& L = *Lp;
    L.k = k;
    L.scale = std::ldexp(1.0, k);
    index<D> nodes;
    for (int d = 0; d < D; ++d) nodes[d] = dom_.nodes(k, d);
    collectively(comm_, [&] { L.own.init(nodes, false); });

    // This rank's tiles, the tiles of each control point's stencil (found
    // once: for omega, the ghosts and the fits) and partial omega
    forOwnStencils(L, [&](std::size_t, const stencil<D>& st) {
        insertStencil(L.own, st);
    });
    const std::int64_t nOwn = L.own.size();
    std::vector<stencilTiles<D>> ownIds(ctrlOrder_.size());
    hugeVector<double> ownW(nOwn*npt*nw_, 0.0);     // (may become the view's omega)
    std::size_t pos = 0;
    forOwnStencils(L, [&](std::size_t i, const stencil<D>& st) {
        findTiles(L.own, st, ownIds[pos]);
        detail::visitStencil(ownIds[pos++], st, [&](std::int64_t id, int n, double w) {
            double* o = &ownW[(id*npt + n)*nw_];
            if (nw_ == 1) o[0] += w*w;
            else for (int c = 0; c < nw_; ++c) if (mask_[i*nc_ + c]) o[c] += w*w;
        });
    });

    // Buckets of own tiles, their index boxes all-gathered; requests for the
    // remote buckets that meet this rank's query stencils
    L.sendTiles.assign(P, {});
    L.recvTiles.assign(P, {});
    std::vector<std::vector<std::uint64_t>> keysGot(P);
    std::vector<std::vector<double>> omegaGot(P);
    if (P > 1)
    {
        const auto buckets = bisect<D>(nOwn, [&](std::int64_t id) {
            const index<D> t = L.own.coord(L.own.keyOf(id));
            std::array<double, D> x;
            for (int d = 0; d < D; ++d) x[d] = double(t[d]);
            return x;
        }, p_.bucketTiles);
        std::vector<std::int64_t> myBoxes;
        for (const auto& g : buckets)
        {
            indexBox<D> bb;
            bb.lo.fill(INT64_MAX);
            bb.hi.fill(INT64_MIN);
            for (auto id : g)
            {
                const index<D> t = L.own.coord(L.own.keyOf(id));
                for (int d = 0; d < D; ++d) { bb.lo[d] = std::min(bb.lo[d], t[d]); bb.hi[d] = std::max(bb.hi[d], t[d]); }
            }
            myBoxes.insert(myBoxes.end(), bb.lo.begin(), bb.lo.end());
            myBoxes.insert(myBoxes.end(), bb.hi.begin(), bb.hi.end());
        }
        L.stats.buckets = std::int64_t(buckets.size());
        const auto allBoxes = comm_.allGather(myBoxes);

        // Query stencils at this level, as tile boxes
        std::vector<indexBox<D>> qt;
        indexBox<D> all;
        all.lo.fill(INT64_MAX);
        all.hi.fill(INT64_MIN);
        for (const auto& qb : queryBoxes_)
        {
            const point<D> ulo = scaled<D>(dom_.local0(qb.lo.data()), L.scale);
            const point<D> uhi = scaled<D>(dom_.local0(qb.hi.data()), L.scale);
            indexBox<D> t;
            for (int d = 0; d < D; ++d)
            {
                t.lo[d] = std::int64_t(std::floor(ulo[d]))/tileEdge;
                t.hi[d] = (std::int64_t(std::floor(uhi[d])) + 3)/tileEdge;
                all.lo[d] = std::min(all.lo[d], t.lo[d]);
                all.hi[d] = std::max(all.hi[d], t.hi[d]);
            }
            qt.push_back(t);
        }
        // Remote bucket boxes that meet a cluster's stencils: ask their owner
        // for exactly the tiles the cluster's point stencils touch
        std::vector<indexBox<D>> remote;
        std::vector<int> remoteRank;
        for (int r = 0; r < P; ++r)
        {
            if (r == me || qt.empty()) continue;
            const auto& v = allBoxes[r];
            for (std::size_t b = 0; b < v.size()/(2*D); ++b)
            {
                indexBox<D> rb;
                for (int d = 0; d < D; ++d) { rb.lo[d] = v[2*D*b + d]; rb.hi[d] = v[2*D*b + D + d]; }
                if (rb.intersects(all)) { remote.push_back(rb); remoteRank.push_back(r); }
            }
        }
        std::vector<std::vector<std::uint64_t>> requests(P);
        std::vector<hashMap> requested(P);
        std::vector<std::size_t> hits;
        for (std::size_t g = 0; g < qt.size() && !remote.empty(); ++g)
        {
            hits.clear();
            for (std::size_t b = 0; b < remote.size(); ++b) if (remote[b].intersects(qt[g])) hits.push_back(b);
            if (hits.empty()) continue;
            for (const double* x : queryGroups_[g])
            {
                const point<D> u = scaled<D>(dom_.local0(x), L.scale);
                forEachIndex<D>(stencil<D>(u.data()).tiles(), [&](const index<D>& t) {
                    for (const std::size_t b : hits)
                    {
                        if (!remote[b].contains(t)) continue;
                        const int r = remoteRank[b];
                        const std::uint64_t key = L.own.key(t);
                        const std::size_t before = requested[r].size();
                        requested[r].insert(key, 0);
                        if (requested[r].size() != before) requests[r].push_back(key);
                    }
                });
            }
        }
        const auto wanted = comm_.exchange(requests);
        std::vector<std::vector<std::uint64_t>> keys(P);
        std::vector<std::vector<double>> om(P);
        for (int r = 0; r < P; ++r)
        {
            for (const std::uint64_t key : wanted[r])
            {
                const std::int64_t id = L.own.findKey(key);
                if (id < 0) continue;
                L.sendTiles[r].push_back(id);
                keys[r].push_back(key);
                om[r].insert(om[r].end(), ownW.begin() + id*npt*nw_, ownW.begin() + (id + 1)*npt*nw_);
            }
        }
        keysGot = comm_.exchange(keys);
        omegaGot = comm_.exchange(om);

        // Ghost mode towards r when this rank's points that touch the tiles r
        // asked for cost less per apply (nc values each) than the tiles (npt*nc)
        L.ghostSend.assign(P, {});
        std::vector<std::vector<double>> gx(P);
        std::vector<std::uint8_t> asked(nOwn);
        for (int r = 0; r < P; ++r)
        {
            if (L.sendTiles[r].empty()) continue;
            std::fill(asked.begin(), asked.end(), 0);
            for (const std::int64_t id : L.sendTiles[r]) asked[id] = 1;
            std::vector<std::uint32_t> g;
            for (std::size_t q = 0; q < ctrlOrder_.size(); ++q)
                for (const std::int32_t id : ownIds[q])
                    if (id >= 0 && asked[id]) { g.push_back(ctrlOrder_[q]); break; }
            if (g.size() >= std::size_t(npt)*L.sendTiles[r].size()) continue;
            for (const std::uint32_t i : g)
            {
                gx[r].insert(gx[r].end(), ctrl_[i], ctrl_[i] + D);
                for (int c = 0; c < nc_; ++c) gx[r].push_back(mask_.empty() || mask_[i*nc_ + c] ? 1.0 : 0.0);
            }
            L.ghostSend[r] = std::move(g);
        }
        L.ghostX = comm_.exchange(gx);
    }

    // The view: own and received tiles, dense when that is not much larger
    std::int64_t upper = nOwn;
    for (const auto& kg : keysGot) upper += std::int64_t(kg.size());
    std::int64_t denseTiles = 1;
    for (int d = 0; d < D; ++d) denseTiles *= (nodes[d] + tileEdge - 1)/tileEdge;
    const bool dense = denseTiles <= 2*upper + 64;
    if (P == 1 && !dense)
    {
        // Serial and sparse: the own tiles and partial omega are the view
        L.view = std::move(L.own);
        L.own = tileLayout<D>();
        L.ownIsView = true;
        L.invOmega = std::move(ownW);
    }
    else
    {
        L.view.init(nodes, dense);
        std::vector<std::int64_t> ownToView(nOwn);
        for (std::int64_t id = 0; id < nOwn; ++id) ownToView[id] = L.view.findOrInsertKey(L.own.keyOf(id));
        for (int r = 0; r < P; ++r)
            for (auto key : keysGot[r]) L.recvTiles[r].push_back(L.view.findOrInsertKey(key));
        for (auto& tiles : L.sendTiles)
            for (auto& id : tiles) id = ownToView[id];
        std::vector<std::uint8_t> shared(L.view.size(), 0);
        for (std::int64_t id = 0; id < nOwn; ++id) shared[ownToView[id]] = 1;
        for (int r = 0; r < me; ++r)
            for (auto id : L.recvTiles[r])
                if (shared[id] == 1) { shared[id] = 2; L.lowShared.push_back(id); }

        // omega: partial sums added in rank order
        L.invOmega.assign(L.view.size()*npt*nw_, 0.0);
        for (int r = 0; r < P; ++r)
        {
            if (r == me)
            {
                for (std::int64_t id = 0; id < nOwn; ++id)
                    for (int j = 0; j < npt*nw_; ++j) L.invOmega[ownToView[id]*npt*nw_ + j] += ownW[id*npt*nw_ + j];
            }
            else
            {
                const auto& og = omegaGot[r];
                for (std::size_t t = 0; t < L.recvTiles[r].size(); ++t)
                    for (int j = 0; j < npt*nw_; ++j) L.invOmega[L.recvTiles[r][t]*npt*nw_ + j] += og[t*npt*nw_ + j];
            }
        }
    }
    if (L.ownIsView) L.ctrlView = std::move(ownIds);
    else
    {
        L.ctrlView.resize(ctrlOrder_.size());
        pos = 0;
        forOwnStencils(L, [&](std::size_t, const stencil<D>& st) { findTiles(L.view, st, L.ctrlView[pos++]); });
    }

    // Separated: at every node of every own stencil, in every component the
    // point constrains, omega (the sum over all ranks) is this point's own
    // w^2 alone, summed as the plan summed it (0 + w*w: exact), also at nodes
    // where its weight is 0
    // (a coarse level fails at its first points)
    bool alone = true;
    for (std::size_t q = 0; q < ctrlOrder_.size() && alone; ++q)
    {
        const std::size_t i = ctrlOrder_[q];
        detail::visitStencil(L.ctrlView[q], ctrlStencil(L, q), [&](std::int64_t id, int n, double w) {
            const double* o = &L.invOmega[(id*npt + n)*nw_];
            for (int c = 0; c < nw_; ++c)
                if (nw_ == 1 || mask_[i*nc_ + c]) alone = alone && o[c] == w*w;
        });
    }
    L.separated = comm_.max(alone ? 0.0 : 1.0) == 0;
    for (double& o : L.invOmega) o = o > 0 ? 1/o : 0.0;

    // The ghosts' stencil tiles, numbered as the tiles received from their rank
    L.ghostTiles.assign(P, {});
    for (int r = 0; r < P && P > 1; ++r)
    {
        if (L.ghostX[r].empty()) continue;
        std::vector<std::int32_t> at(L.view.size(), -1);
        for (std::size_t t = 0; t < L.recvTiles[r].size(); ++t) at[L.recvTiles[r][t]] = std::int32_t(t);
        const std::size_t stride = D + nc_, ng = L.ghostX[r].size()/stride;
        L.ghostTiles[r].resize(ng);
        for (std::size_t g = 0; g < ng; ++g)
        {
            stencilTiles<D>& tid = L.ghostTiles[r][g];
            findTiles(L.view, stencil<D>(scaled<D>(dom_.local0(&L.ghostX[r][g*stride]), L.scale).data()), tid);
            for (std::int32_t& id : tid) if (id >= 0) id = at[id];
        }
    }
    for (const auto& g : L.ghostSend) L.ghosts = L.ghosts || !g.empty();
    for (const auto& g : L.ghostTiles) L.ghosts = L.ghosts || !g.empty();
    L.phi.assign(L.view.size()*npt*nc_, 0.0);
    precondition(L.view.size() < (std::int64_t(1) << 31), "mba: more than 2^31 tiles in one level");
    if (L.separated)
    {
        // every point's phi is stored until fold() has found the tiles read
        L.readEveryFit.assign(ctrlOrder_.size(), 1);
        L.rr.assign(ctrlOrder_.size()*nc_, 0.0);
    }

    levelStats& s = L.stats;
    s.level = k;
    s.h = dom_.h0/L.scale;
    s.ownTiles = L.ownTiles().size();
    s.viewTiles = L.view.size();
    s.dense = L.view.dense();
    s.separated = L.separated;
    s.nodes = L.view.size()*npt;
    s.bytes = std::int64_t((L.phi.capacity() + L.invOmega.capacity())*sizeof(double)
        + L.own.bytes() + L.view.bytes() + L.lowShared.capacity()*sizeof(std::int64_t)
        + L.ctrlView.capacity()*sizeof(stencilTiles<D>) + L.readEveryFit.capacity() + L.rr.capacity()*sizeof(double));
    for (int r = 0; r < P && P > 1; ++r)
    {
        s.tilesSent += std::int64_t(L.sendTiles[r].size());
        s.tilesReceived += std::int64_t(L.recvTiles[r].size());
        s.messagesSent += !L.sendTiles[r].empty();
        s.messagesReceived += !L.recvTiles[r].empty();
        s.ghostsSent += std::int64_t(L.ghostSend[r].size());
        s.ghostsReceived += std::int64_t(L.ghostTiles[r].size());
        const std::int64_t vs = L.ghostSend[r].empty() ? std::int64_t(L.sendTiles[r].size())*npt*nc_
            : std::int64_t(L.ghostSend[r].size())*nc_;
        const std::int64_t vr = L.ghostTiles[r].empty() ? std::int64_t(L.recvTiles[r].size())*npt*nc_
            : std::int64_t(L.ghostTiles[r].size())*nc_;
        s.bytesSentPerApply += vs*std::int64_t(sizeof(double));
        s.bytesReceivedPerApply += vr*std::int64_t(sizeof(double));
        s.bytes += std::int64_t(L.ghostX[r].capacity()*sizeof(double)
            + L.ghostTiles[r].capacity()*sizeof(stencilTiles<D>));
    }
    s.planSeconds = now() - t0;
    levels_.push_back(std::move(Lp));
}

template <int D>
void multilevel<D>::applyLevel(level& L)
{
    constexpr int npt = level::npt;
    const int P = comm_.size(), me = comm_.rank();
    const int blk = npt*nc_;
    // delta += w^2 phi_c = w^3 r_c / sum(w^2): this rank's partial sums, in
    // the view; in parallel the other ranks' are then added in rank order.
    // Separated: phi itself is stored at the nodes of the own points that
    // are read every fit (always the same nodes; no other point writes
    // there), and only the tiles that other ranks' values are added to are
    // cleared. The other points' nodes keep older values, read by nobody
    // until completeLattices() stores them.
    if (!L.separated) std::fill(L.phi.begin(), L.phi.end(), 0.0);
    else
        for (const auto& tiles : L.recvTiles)
            for (const std::int64_t id : tiles) std::fill(&L.phi[id*blk], &L.phi[(id + 1)*blk], 0.0);
    // The stencils (again for the residuals below) and, for the scatter,
    // their cubed weights, in a pass of their own: the scatter's vector loads
    // then read weights stored long before (loads of values just stored in
    // smaller pieces stall until the stores retire)
    const std::size_t nq = ctrlOrder_.size();
    stencils_.resize(nq);
    cubed_.resize(L.separated ? 0 : nq);
    for (std::size_t q = 0; q < nq; ++q)
    {
        stencils_[q] = ctrlStencil(L, q);
        if (!L.separated) cubed_[q] = stencils_[q].cubedWeights();
    }
    // r/sum(w^2) per point
    std::vector<double>& rr = L.separated ? L.rr : rr_;
    rr.resize(nq*nc_);
    for (std::size_t q = 0; q < nq; ++q)
    {
        const std::size_t i = ctrlOrder_[q];
        const double isw = 1/stencils_[q].sumSquares();
        for (int c = 0; c < nc_; ++c)
            rr[q*nc_ + c] = (mask_.empty() || mask_[i*nc_ + c]) ? residual_[i*nc_ + c]*isw : 0.0;
    }
    if (L.separated)
    {
        for (std::size_t q = 0; q < nq; ++q)
        {
            bool on[3];
            if (L.readEveryFit[q])
                scatterSeparated<D>(L.phi.data(), nc_, L.ctrlView[q], stencils_[q], &rr[q*nc_], constrained(ctrlOrder_[q], on));
        }
    }
    else
    {
        // Runs of points with the same stencil nodes at once (coarse levels);
        // short runs point after point, and every point at a level with
        // ghosts, as the ranks holding them as ghosts form their sums
        const std::size_t shortest = L.ghosts ? nq + 1 : minRun;
        for (std::size_t q = 0, e; q < nq; q = e)
        {
            for (e = q + 1; e < nq && stencils_[e].base == stencils_[q].base; ++e) {}
            if (e - q >= shortest) scatterRun<D>(L.phi.data(), nc_, L.ctrlView[q], &cubed_[q], &rr[q*nc_], e - q);
            else for (std::size_t j = q; j < e; ++j) scatter<D>(L.phi.data(), nc_, L.ctrlView[j], cubed_[j], &rr[j*nc_]);
        }
    }
    L.complete = !L.separated;

    if (P > 1)
    {
        // Exchange the partial delta of the requested tiles, or the residuals
        // of the ghosts
        std::vector<std::vector<double>> send(P);
        for (int r = 0; r < P; ++r)
        {
            if (!L.ghostSend[r].empty())
            {
                for (const std::uint32_t i : L.ghostSend[r])
                    send[r].insert(send[r].end(), &residual_[i*nc_], &residual_[i*nc_] + nc_);
                continue;
            }
            send[r].reserve(L.sendTiles[r].size()*blk);
            for (auto id : L.sendTiles[r]) send[r].insert(send[r].end(), &L.phi[id*blk], &L.phi[(id + 1)*blk]);
        }
        std::vector<std::vector<double>> got = comm_.exchange(send);

        // The ghosts' rank's partial delta, as it computes it
        const std::size_t stride = D + nc_;
        for (int r = 0; r < P; ++r)
        {
            if (L.ghostTiles[r].empty()) continue;
            std::vector<double> dl(L.recvTiles[r].size()*blk, 0.0);
            for (std::size_t g = 0; g < L.ghostTiles[r].size(); ++g)
            {
                const double* x = &L.ghostX[r][g*stride];
                const point<D> u = scaled<D>(dom_.local0(x), L.scale);
                const stencil<D> st(u.data());
                const double isw = 1/st.sumSquares();
                double rr[3] = {0, 0, 0};
                bool on[3];
                for (int c = 0; c < nc_; ++c)
                {
                    on[c] = x[D + c] != 0;
                    rr[c] = on[c] ? got[r][g*nc_ + c]*isw : 0.0;
                }
                // as the owner does
                if (L.separated) scatterSeparated<D>(dl.data(), nc_, L.ghostTiles[r][g], st, rr, nw_ == 1 ? nullptr : on);
                else scatter<D>(dl.data(), nc_, L.ghostTiles[r][g], st.cubedWeights(), rr);
            }
            got[r].swap(dl);
        }

        // Sum over ranks, in rank order (every rank holding a node adds the
        // same partial sums in the same order: bitwise the same delta). This
        // rank's own sums are in place already; where a lower rank
        // contributes too they are set aside and added at this rank's turn.
        std::vector<double>& own = scratch_;
        own.resize(L.lowShared.size()*blk);
        for (std::size_t t = 0; t < L.lowShared.size(); ++t)
        {
            double* ph = &L.phi[L.lowShared[t]*blk];
            std::copy(ph, ph + blk, &own[t*blk]);
            std::fill(ph, ph + blk, 0.0);
        }
        auto add = [&](std::int64_t id, const double* dl) {
            double* ph = &L.phi[id*blk];
            for (int j = 0; j < blk; ++j) ph[j] += dl[j];
        };
        for (int r = 0; r < P; ++r)
        {
            if (r == me)
                for (std::size_t t = 0; t < L.lowShared.size(); ++t) add(L.lowShared[t], &own[t*blk]);
            else
                for (std::size_t t = 0; t < L.recvTiles[r].size(); ++t) add(L.recvTiles[r][t], &got[r][t*blk]);
        }
    }
    // phi = delta/omega (no contribution where omega is 0: delta is 0 there
    // too); separated levels hold phi already
    if (!L.separated)
    {
        switch (nw_ == 1 ? nc_ : 1)     // one 1/omega per node, or per value
        {
            case 1: scaleNodes<1>(L.phi.data(), L.invOmega.data(), L.invOmega.size()); break;
            case 2: scaleNodes<2>(L.phi.data(), L.invOmega.data(), L.invOmega.size()); break;
            default: scaleNodes<3>(L.phi.data(), L.invOmega.data(), L.invOmega.size());
        }
    }

    // Residuals at this rank's control points
    if (L.separated)
    {
        for (std::size_t q = 0; q < ctrlOrder_.size(); ++q)
        {
            const std::size_t i = ctrlOrder_[q];
            const double sw = stencils_[q].sumSquares();
            for (int c = 0; c < nc_; ++c) residual_[i*nc_ + c] -= L.rr[q*nc_ + c]*sw;
        }
        return;
    }
    // (the level's values first, in a pass of their own: subtracting each
    // right after its sum was stored in pieces would stall on the loads)
    atCtrl_.assign(nq*nc_, 0.0);
    for (std::size_t q = 0, e; q < nq; q = e)
    {
        for (e = q + 1; e < nq && stencils_[e].base == stencils_[q].base; ++e) {}
        if (e - q >= minBlockRun) evalRun<D>(L.phi.data(), nc_, L.ctrlView[q], &stencils_[q], e - q, &atCtrl_[q*nc_]);
        else
            for (std::size_t j = q; j < e; ++j) evalStencil(L.phi.data(), nc_, L.ctrlView[j], stencils_[j], &atCtrl_[j*nc_]);
    }
    for (std::size_t q = 0; q < nq; ++q)
    {
        const std::size_t i = ctrlOrder_[q];
        for (int c = 0; c < nc_; ++c) residual_[i*nc_ + c] -= atCtrl_[q*nc_ + c];
    }
}

template <int D>
void multilevel<D>::residualStats(double& maxr, double& rms) const
{
    // (four partial maxima and sums: independent chains)
    double m[4] = {0, 0, 0, 0}, s[4] = {0, 0, 0, 0};
    const bool all = mask_.empty();
    const std::size_t nv = ctrl_.size*nc_;
    for (std::size_t j = 0; j < nv; ++j)
    {
        const double r = all || mask_[j] ? residual_[j] : 0.0;
        m[j & 3] = std::max(m[j & 3], std::abs(r));
        s[j & 3] += r*r;
    }
    const double n = all ? double(nv) : double(nv - std::count(mask_.begin(), mask_.end(), std::uint8_t(0)));
    maxr = comm_.max(std::max(std::max(m[0], m[1]), std::max(m[2], m[3])));
    const std::vector<double> sn = comm_.sum(std::vector<double>{(s[0] + s[1]) + (s[2] + s[3]), n});
    rms = sn[1] > 0 ? std::sqrt(sn[0]/sn[1]) : 0.0;
}

template <int D>
const fitReport& multilevel<D>::fit(const std::vector<double>& values)
{
    const double t0 = now();
    double vmax = 0;
    collectively(comm_, [&] {
        precondition(values.size() == ctrl_.size*nc_,
            "mba: " + std::to_string(values.size()) + " control values, expected "
            + std::to_string(ctrl_.size*nc_) + " (control points x components)");
        for (std::size_t i = 0; i < values.size(); ++i)
        {
            if (!(mask_.empty() || mask_[i])) continue;
            if (!std::isfinite(values[i]))
                precondition(false, "mba: control value " + std::to_string(i/nc_) + " component "
                    + std::to_string(i%nc_) + " is not finite");
            vmax = std::max(vmax, std::abs(values[i]));
        }
    });
    fitReport& rep = report_;
    rep = fitReport();
    rep.maxValue = comm_.max(vmax);
    rep.threshold = p_.relative ? p_.tolerance*rep.maxValue : p_.tolerance;

    residual_ = values;
    if (p_.affine)
    {
        affine_.solve(comm_, ctrl_, mask_, values);
        for (std::size_t i = 0; i < ctrl_.size; ++i)
        {
            double g[3] = {0, 0, 0};
            affine_.addTo(ctrl_[i], g);
            for (int c = 0; c < nc_; ++c) residual_[i*nc_ + c] -= g[c];
        }
    }
    double maxr, rms;
    residualStats(maxr, rms);
    rep.initialMaxResidual = maxr;
    int k = 0;
    while (!(maxr <= rep.threshold) && k < p_.maxLevels)
    {
        if (k == int(levels_.size())) buildLevel(k);
        const double t1 = now();
        applyLevel(*levels_[k]);
        residualStats(maxr, rms);
        levelStats& s = levels_[k]->stats;
        s.maxResidual = maxr;
        s.rmsResidual = rms;
        s.seconds = now() - t1;
        ++k;
    }
    rep.levels = k;
    fold();
    rep.maxResidual = maxr;
    rep.rmsResidual = rms;
    rep.converged = maxr <= rep.threshold;
    rep.seconds = now() - t0;
    return rep;
}

namespace {

template <int D>
double boxNodes(const indexBox<D>& b)
{
    double n = 1;
    for (int d = 0; d < D; ++d) n *= double(b.hi[d] - b.lo[d] + 1);
    return n;
}

/// Coarse parents of fine node jf in one direction (uniform cubic B-spline
/// subdivision; node j lies at lo + (j - 1) h): fine node 2j - 1 = (P[j-1] +
/// 6 P[j] + P[j+1])/8, fine node 2j = (P[j] + P[j+1])/2. Parents outside
/// [lo, hi] are left out.
inline int parents(std::int64_t jf, std::int64_t lo, std::int64_t hi, std::int64_t* j, double* w)
{
    int n = 0;
    auto add = [&](std::int64_t i, double wt) { if (i >= lo && i <= hi) { j[n] = i; w[n] = wt; ++n; } };
    if (jf % 2 == 0) { add(jf/2, 0.5); add(jf/2 + 1, 0.5); }
    else { const std::int64_t c = (jf + 1)/2; add(c - 1, 0.125); add(c, 0.75); add(c + 1, 0.125); }
    return n;
}

/// Values G (nc per node) on the node box cb of one level, refined to the next
/// level on the node box fb, one direction at a time (the parents of fb's
/// nodes that the stencils of points inside the boxes use lie in cb)
template <int D>
void refine(hugeVector<double>& G, const indexBox<D>& cb, const indexBox<D>& fb, int nc, hugeVector<double>& T)
{
    index<D> n;
    for (int d = 0; d < D; ++d) n[d] = cb.hi[d] - cb.lo[d] + 1;
    std::vector<std::int64_t> pj;
    std::vector<double> pw;
    for (int d = 0; d < D; ++d)
    {
        std::int64_t outer = 1, inner = nc;
        for (int e = 0; e < d; ++e) outer *= n[e];
        for (int e = d + 1; e < D; ++e) inner *= n[e];
        const std::int64_t nf = fb.hi[d] - fb.lo[d] + 1, nco = n[d];
        // Three parents a fine node (a missing one with weight 0 at coarse
        // node 0: the same sums)
        pj.assign(3*nf, 0);
        pw.assign(3*nf, 0.0);
        for (std::int64_t jf = 0; jf < nf; ++jf)
        {
            const int np = parents(fb.lo[d] + jf, cb.lo[d], cb.hi[d], &pj[3*jf], &pw[3*jf]);
            for (int q = 0; q < np; ++q) pj[3*jf + q] -= cb.lo[d];
        }
        T.resize(std::size_t(outer*nf*inner));
        for (std::int64_t o = 0; o < outer; ++o)
            for (std::int64_t jf = 0; jf < nf; ++jf)
            {
                double* t = &T[(o*nf + jf)*inner];
                const double* g0 = &G[(o*nco + pj[3*jf])*inner];
                const double* g1 = &G[(o*nco + pj[3*jf + 1])*inner];
                const double* g2 = &G[(o*nco + pj[3*jf + 2])*inner];
                const double w0 = pw[3*jf], w1 = pw[3*jf + 1], w2 = pw[3*jf + 2];
                for (std::int64_t i = 0; i < inner; ++i) t[i] = w0*g0[i] + w1*g1[i] + w2*g2[i];
            }
        n[d] = nf;
        G.swap(T);
    }
}

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
    typedef detail::vec<4>::type v4d;
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

template <int D>
indexBox<D> multilevel<D>::evalNodeBox(int k) const
{
    const double s = std::ldexp(1.0, k);
    indexBox<D> b;
    for (int d = 0; d < D; ++d)
    {
        b.lo[d] = std::int64_t(std::floor(evalLo0_[d]*s));
        b.hi[d] = std::int64_t(std::floor(evalHi0_[d]*s)) + 3;
    }
    return b;
}

template <int D>
void multilevel<D>::completeLattices() const
{
    for (const auto& Lp : levels_)
    {
        // (phi of a separated level's points that no planned reader needs:
        // stored on demand, the lattice's value does not change)
        level& L = *Lp;
        if (L.complete) continue;
        std::size_t pos = 0;
        forOwnStencils(L, [&](std::size_t i, const stencil<D>& st) {
            bool on[3];
            if (!L.readEveryFit[pos])
                scatterSeparated<D>(L.phi.data(), nc_, L.ctrlView[pos], st, &L.rr[pos*nc_], constrained(i, on));
            ++pos;
        });
        L.complete = true;
    }
}

template <int D>
void multilevel<D>::fold()
{
    constexpr int npt = level::npt;
    flat_ = -1;
    flatPhi_.clear();
    if (eval_.size == 0) return;
    const double budget = double(std::max<std::size_t>(eval_.size, 4096));
    int m = -1;
    while (m + 1 < report_.levels && boxNodes<D>(evalNodeBox(m + 1)) <= budget) ++m;
    if (m < 0) return;
    // flatPhi_ and foldScratch_ keep their storage from fit to fit
    hugeVector<double>& G = flatPhi_;
    hugeVector<double>& T = foldScratch_;
    indexBox<D> gb;
    for (int k = 0; k <= m; ++k)
    {
        const indexBox<D> fb = evalNodeBox(k);
        if (k == 0)
        {
            // the affine approximation: cubic B-splines reproduce linear
            // functions, node j (u = j - 1 in level units) taking the
            // function's value there; refined with the levels (exactly)
            G.assign(std::size_t(boxNodes<D>(fb))*nc_, 0.0);
            forEachIndex<D>(fb, [&](const index<D>& j) {
                double x[D];
                for (int d = 0; d < D; ++d) x[d] = dom_.lo[d] + double(j[d] - 1)*dom_.h0;
                affine_.addTo(x, &G[boxIndex<D>(fb, j)*nc_]);
            });
        }
        else refine<D>(G, gb, fb, nc_, T);
        gb = fb;
        // + this level's coefficients in the box
        const level& L = *levels_[k];
        for (std::int64_t id = 0; id < L.view.size(); ++id)
        {
            const index<D> t = L.view.coord(L.view.keyOf(id));
            indexBox<D> tb, nb;     // the tile's nodes; those in the box
            bool inside = true;
            for (int d = 0; d < D; ++d)
            {
                tb.lo[d] = t[d]*tileEdge;
                tb.hi[d] = tb.lo[d] + tileEdge - 1;
                nb.lo[d] = std::max(tb.lo[d], gb.lo[d]);
                nb.hi[d] = std::min(tb.hi[d], gb.hi[d]);
                inside = inside && nb.lo[d] <= nb.hi[d];
            }
            if (!inside) continue;
            forEachIndex<D>(nb, [&](const index<D>& j) {
                const double* p = &L.phi[(id*npt + boxIndex<D>(tb, j))*nc_];
                double* o = &G[boxIndex<D>(gb, j)*nc_];
                for (int c = 0; c < nc_; ++c) o[c] += p[c];
            });
        }
    }
    flatBox_ = gb;
    flat_ = m;

    // Which finer levels have coefficients at each evaluation point (the
    // same as long as the levels and flat_ are): levels whose lattice has a
    // node with omega > 0 and a non-zero weight in the point's stencil.
    // Where a level has no tile at the stencil, no finer level has one
    // (their nodes lie within the stencils of the same control points).
    // For separated levels this also finds the tiles that evaluation reads.
    const std::pair<int, int> key(int(levels_.size()), flat_);
    if (key == deepKey_) return;
    precondition(int(levels_.size()) - flat_ - 1 <= 32, "mba: more than 32 levels above the flat lattice");
    deepLevels_.clear();
    deepTiles_.clear();
    std::vector<std::vector<std::uint8_t>> read(levels_.size());
    for (int k = flat_ + 1; k < int(levels_.size()); ++k)
        if (levels_[k]->separated) read[k].assign(levels_[k]->view.size(), 0);
    stencilTiles<D> tid;
    for (std::size_t q = 0; q < eval_.size; ++q)
    {
        const point<D>& u0 = evalU0_[q];
        std::uint32_t m = 0;
        for (int k = flat_ + 1; k < int(levels_.size()); ++k)
        {
            const level& L = *levels_[k];
            const stencil<D> st(scaled<D>(u0, L.scale).data());
            if (!findTiles(L.view, st, tid)) break;
            // (weights are >= 0: the weighted sum of 1/omega is > 0 exactly
            // where a node of non-zero weight has coefficients)
            double w[3] = {0, 0, 0};
            evalStencil(L.invOmega.data(), nw_, tid, st, w);
            if (!(w[0] + w[1] + w[2] > 0)) continue;
            m |= std::uint32_t(1) << (k - flat_ - 1);
            deepTiles_.push_back(tid);
            if (!read[k].empty()) for (const std::int32_t id : tid) if (id >= 0) read[k][id] = 1;
        }
        if (m) deepLevels_.emplace_back(std::uint32_t(q), m);
    }
    deepLevels_.shrink_to_fit();
    deepTiles_.shrink_to_fit();
    deepKey_ = key;

    // Separated levels: the points whose phi is stored in every fit are
    // those with a tile read by the evaluation or sent as a tile to another
    // rank; all of them where the level is folded into the flat lattice
    for (int k = 0; k < int(levels_.size()); ++k)
    {
        level& L = *levels_[k];
        if (!L.separated) continue;
        if (k <= flat_)
        {
            std::fill(L.readEveryFit.begin(), L.readEveryFit.end(), 1);
            continue;
        }
        for (int r = 0; r < comm_.size() && comm_.size() > 1; ++r)
            if (L.ghostSend[r].empty())
                for (const std::int64_t id : L.sendTiles[r]) read[k][id] = 1;
        for (std::size_t q = 0; q < ctrlOrder_.size(); ++q)
        {
            L.readEveryFit[q] = 0;
            for (const std::int32_t id : L.ctrlView[q]) if (id >= 0 && read[k][id]) L.readEveryFit[q] = 1;
        }
    }
}

template <int D>
void multilevel<D>::addLevels(const double* x, double* out, int nLevels) const
{
    affine_.addTo(x, out);
    const point<D> u0 = dom_.local0(x);
    for (int k = 0; k < nLevels; ++k)
    {
        const level& L = *levels_[k];
        // No stored tile here: none at finer levels either (their nodes lie
        // within the stencils of the same control points)
        if (!evalStencil(L.view, L.phi.data(), nc_, stencil<D>(scaled<D>(u0, L.scale).data()), out)) break;
    }
}

template <int D>
void multilevel<D>::evaluate(std::vector<double>& out) const
{
    if (flat_ < 0)
    {
        out.assign(eval_.size*nc_, 0.0);
        for (std::size_t q = 0; q < eval_.size; ++q) addLevels(eval_[evalAt(q)], &out[evalAt(q)*nc_], report_.levels);
        return;
    }
    // The flat lattice point after point in evaluation order, then the finer
    // levels at the points that have tiles there. In the points' own order
    // the results are written in place; in curve order into sweep_, from
    // which the points' own order then gathers them (the reads and writes of
    // points and results stay in sequence)
    const bool own = evalOrder_.empty();
    if (out.capacity() < eval_.size*nc_)
    {
        // (a new array: on huge pages where the kernel takes the advice)
        std::vector<double>().swap(out);
        out.reserve(eval_.size*nc_);
        adviseHugePages(out.data(), eval_.size*nc_*sizeof(double));
    }
    out.resize(eval_.size*nc_);     // (every value is written below)
    if (!own) sweep_.resize(eval_.size*nc_);
    double* dst = own ? out.data() : sweep_.data();
    const double sf = std::ldexp(1.0, flat_);
#ifdef MBA_WIDE_VECTORS
    if (wideVectors())
        flatSweepWide<D>(flatPhi_.data(), flatBox_, nc_, sf, evalU0_.data(), eval_.size, dst);
    else
#endif
        flatSweep<D, 2>(flatPhi_.data(), flatBox_, nc_, sf, evalU0_.data(), eval_.size, dst);

    // + the finer levels, in a pass of their own over the points that have them
    const stencilTiles<D>* tiles = deepTiles_.data();
    for (const auto& qm : deepLevels_)
    {
        const std::size_t q = qm.first;
        int k = flat_ + 1;
        for (std::uint32_t m = qm.second; m; m >>= 1, ++k)
        {
            if (!(m & 1)) continue;
            if (k < report_.levels)
            {
                const level& L = *levels_[k];
                evalStencil(L.phi.data(), nc_, *tiles, stencil<D>(scaled<D>(evalU0_[q], L.scale).data()), &dst[q*nc_]);
            }
            ++tiles;
        }
    }
    for (std::size_t i = 0; i < eval_.size && !own; ++i)
    {
        const double* v = &sweep_[std::size_t(evalPos_[i])*nc_];
        for (int c = 0; c < nc_; ++c) out[i*nc_ + c] = v[c];
    }
}

template <int D>
void multilevel<D>::evaluate(const double* x, double* out) const
{
    if (comm_.size() != 1)
        throw std::logic_error("mba: evaluation at unplanned points needs the serial communicator");
    completeLattices();
    for (int c = 0; c < nc_; ++c) out[c] = 0;
    addLevels(x, out, report_.levels);
}

template <int D>
void multilevel<D>::evaluateControl(std::vector<double>& out) const
{
    completeLattices();
    out.assign(ctrl_.size*nc_, 0.0);
    for (std::size_t i = 0; i < ctrl_.size; ++i) addLevels(ctrl_[i], &out[i*nc_], report_.levels);
}

template <int D>
std::vector<levelStats> multilevel<D>::stats() const
{
    std::vector<levelStats> s;
    for (const auto& L : levels_) s.push_back(L->stats);
    return s;
}

template <int D>
std::int64_t multilevel<D>::bytes() const
{
    std::int64_t b = std::int64_t((residual_.capacity() + rr_.capacity() + scratch_.capacity() + flatPhi_.capacity() + foldScratch_.capacity() + sweep_.capacity())*sizeof(double)
        + active_.capacity() + mask_.capacity() + deepLevels_.capacity()*sizeof(deepLevels_[0]) + deepTiles_.capacity()*sizeof(stencilTiles<D>)
        + (ctrlOrder_.capacity() + evalOrder_.capacity() + evalPos_.capacity())*sizeof(std::uint32_t)
        + (ctrlU0_.capacity() + evalU0_.capacity())*sizeof(point<D>) + (stencils_.capacity() + cubed_.capacity())*sizeof(stencil<D>));
    for (const auto& L : levels_) b += L->stats.bytes;
    return b;
}

template <int D>
std::int64_t multilevel<D>::gatherAllBytes() const
{
    std::int64_t mine = 0;
    for (auto a : active_) mine += a;
    return (nCtrlGlobal_ - mine)*(D + nc_)*std::int64_t(sizeof(double));
}

template class multilevel<2>;
template class multilevel<3>;

} // namespace mba
