// The query clusters of a rank, and whom it asks for which tiles of a level:
// the all-gathered boxes of every rank's buckets of own tiles, and per rank
// the tiles (and their nodes) that its query points' stencils touch there.
#include "levelPlanner.hpp"
#include "buckets.hpp"

#include <algorithm>
#include <cmath>

namespace mba {

template <int D>
queryClusters<D> clusterQueryPoints(const communicator& comm, const controlPoints<D>& ctrl, pointsView<D> eval)
{
    queryClusters<D> clusters;
    if (comm.size() == 1) return clusters;
    std::vector<const double*> q;
    for (std::size_t i = 0; i < ctrl.x.size; ++i) if (ctrl.active[i]) q.push_back(ctrl.x[i]);
    for (std::size_t i = 0; i < eval.size; ++i) q.push_back(eval[i]);
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
        clusters.boxes.push_back(qb);
        clusters.points.push_back(std::move(members));
    }
    return clusters;
}

namespace {

/// An empty index box that any box's add makes that box
template <int D>
indexBox<D> emptyIndexBox()
{
    indexBox<D> b;
    b.lo.fill(INT64_MAX);
    b.hi.fill(INT64_MIN);
    return b;
}

} // namespace

/// Buckets of own tiles, their index boxes (lo, hi) all-gathered: per rank
/// its buckets' boxes, 2D values each
template <int D>
std::vector<std::vector<std::int64_t>> levelPlanner<D>::bucketDirectory()
{
    const tileLayout<D>& own = L_.ownLayout;
    // (the tiles' coordinates decoded once: the bisection compares them often)
    std::vector<index<D>> at(nOwn_);
    for (std::int64_t id = 0; id < nOwn_; ++id) at[id] = own.coord(own.keyOf(id));
    const auto buckets = bisect<D>(nOwn_, [&](std::int64_t id) {
        std::array<double, D> x;
        for (int d = 0; d < D; ++d) x[d] = double(at[id][d]);
        return x;
    }, bucketTiles_);
    std::vector<std::int64_t> myBoxes;
    for (const auto& g : buckets)
    {
        indexBox<D> bb = emptyIndexBox<D>();
        for (auto id : g)
            for (int d = 0; d < D; ++d) { bb.lo[d] = std::min(bb.lo[d], at[id][d]); bb.hi[d] = std::max(bb.hi[d], at[id][d]); }
        myBoxes.insert(myBoxes.end(), bb.lo.begin(), bb.lo.end());
        myBoxes.insert(myBoxes.end(), bb.hi.begin(), bb.hi.end());
    }
    L_.stats.buckets = std::int64_t(buckets.size());
    return comm_.allGather(myBoxes);
}

/// The query clusters' stencils at this level as tile boxes; all: their union
template <int D>
std::vector<indexBox<D>> levelPlanner<D>::clusterTileBoxes(indexBox<D>& all) const
{
    std::vector<indexBox<D>> qt;
    all = emptyIndexBox<D>();
    for (const auto& qb : clusters_.boxes)
    {
        const point<D> ulo = scaled<D>(dom_.local0(qb.lo.data()), L_.scale);
        const point<D> uhi = scaled<D>(dom_.local0(qb.hi.data()), L_.scale);
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
    return qt;
}

/// Per rank the keys of the tiles to ask it for: remote bucket boxes that
/// meet a cluster's stencils, and in them exactly the tiles the cluster's
/// point stencils touch
template <int D>
std::vector<std::vector<std::uint64_t>>
levelPlanner<D>::tileRequests(const std::vector<std::vector<std::int64_t>>& directory) const
{
    indexBox<D> all;
    const std::vector<indexBox<D>> qt = clusterTileBoxes(all);
    std::vector<indexBox<D>> remote;
    std::vector<int> remoteRank;
    for (int r = 0; r < nRanks_; ++r)
    {
        if (r == me_ || qt.empty()) continue;
        const auto& v = directory[r];
        for (std::size_t b = 0; b < v.size()/(2*D); ++b)
        {
            indexBox<D> rb;
            for (int d = 0; d < D; ++d) { rb.lo[d] = v[2*D*b + d]; rb.hi[d] = v[2*D*b + D + d]; }
            if (rb.intersects(all)) { remote.push_back(rb); remoteRank.push_back(r); }
        }
    }
    std::vector<std::vector<std::uint64_t>> requests(nRanks_);
    std::vector<hashMap> requested(nRanks_);
    std::vector<std::size_t> hits;
    std::vector<std::uint64_t> clusterTiles, clusterNodes;
    for (std::size_t g = 0; g < qt.size() && !remote.empty(); ++g)
    {
        hits.clear();
        for (std::size_t b = 0; b < remote.size(); ++b) if (remote[b].intersects(qt[g])) hits.push_back(b);
        if (hits.empty()) continue;
        // the cluster's stencil tiles, each once, in the order first met
        // (the points of a cluster share most of their tiles), and the
        // nodes of each that the stencils read
        hashMap seen;
        clusterTiles.clear();
        clusterNodes.clear();
        index<D> last;   // the previous point's stencil base (a point with the same adds nothing)
        last.fill(-1);
        for (const double* x : clusters_.points[g])
        {
            const point<D> u = scaled<D>(dom_.local0(x), L_.scale);
            index<D> base;
            for (int d = 0; d < D; ++d) base[d] = std::int64_t(u[d]);
            if (base == last) continue;
            last = base;
            const stencil<D> st(u.data());
            forEachIndex<D>(st.tiles(), [&](const index<D>& t) {
                const std::uint64_t key = L_.ownLayout.key(t);
                const std::size_t before = seen.size();
                const std::size_t at = seen.insert(key, before);
                if (seen.size() != before)
                {
                    clusterTiles.push_back(key);
                    clusterNodes.push_back(0);
                }
                clusterNodes[at] |= st.nodesIn(t);
            });
        }
        for (std::size_t c = 0; c < clusterTiles.size(); ++c)
        {
            const std::uint64_t key = clusterTiles[c];
            const index<D> t = L_.ownLayout.coord(key);
            for (const std::size_t b : hits)
            {
                if (!remote[b].contains(t)) continue;
                const int r = remoteRank[b];
                const std::size_t before = requested[r].size();
                const std::size_t at = requested[r].insert(key, before);
                if (requested[r].size() != before) requests[r].insert(requests[r].end(), {key, 0});
                requests[r][2*at + 1] |= clusterNodes[c];
            }
        }
    }
    return requests;
}

template queryClusters<2> clusterQueryPoints<2>(const communicator&, const controlPoints<2>&, pointsView<2>);
template queryClusters<3> clusterQueryPoints<3>(const communicator&, const controlPoints<3>&, pointsView<3>);
template std::vector<std::vector<std::int64_t>> levelPlanner<2>::bucketDirectory();
template std::vector<std::vector<std::int64_t>> levelPlanner<3>::bucketDirectory();
template std::vector<std::vector<std::uint64_t>>
levelPlanner<2>::tileRequests(const std::vector<std::vector<std::int64_t>>&) const;
template std::vector<std::vector<std::uint64_t>>
levelPlanner<3>::tileRequests(const std::vector<std::vector<std::int64_t>>&) const;

} // namespace mba
