// The choice of a level's exchange (params::exchange): direct, chunked or
// the tree, and the latency-bandwidth model that automatic compares them in.
#include "levelPlanner.hpp"
#include "treeSum.hpp"

#include <algorithm>
#include <utility>

namespace mba {

/// Direct, chunked or tree (params::exchange): automatic takes the chunks
/// when the rank that receives most per apply then receives fewer bytes,
/// and the tree when exchangeCost() makes it cheaper than that. A separated
/// level stays direct (its apply stores phi where it is read).
template <int D>
void levelPlanner<D>::chooseExchange()
{
    if (mode_ == params::exchangeMode::direct || L_.separated) return;
    // (automatic on two ranks: the chunks never make a rank receive fewer
    // values; a node it reads that the other rank weighs comes once either
    // way, and as a node's owner it may receive partial sums it does not read)
    const bool chunksCanWin = mode_ != params::exchangeMode::automatic || nRanks_ > 2;
    if (mode_ != params::exchangeMode::tree && chunksCanWin)
    {
        // the nodes this rank reads, per view tile (it asks every holder of a
        // tile for the same nodes)
        std::vector<std::uint64_t> read(L_.view.size(), 0);
        for (const auto& q : requests_)
            for (std::size_t j = 0; j + 1 < q.size(); j += 2)
            {
                const std::int64_t id = L_.view.findKey(q[j]);
                if (id >= 0) read[id] |= q[j + 1];
            }
        chunkExchange X = planChunks<D>(chunkSources<D>{nRanks_, me_, nc_, omegaPerNode_, L_.view, ownToView_,
            L_.tilesFrom, L_.tilesTo, asked_, read, ownMask_, maskFrom_, L_.coefficientNodes, comm_});
        bool take = true;
        if (mode_ == params::exchangeMode::automatic)
        {
            std::int64_t direct = 0, chunked = 0;
            for (int r = 0; r < nRanks_; ++r)
            {
                direct += std::int64_t(L_.receiveCounts[r]);
                chunked += std::int64_t(X.partialCounts[r] + X.fullCounts[r]);
            }
            take = comm_.max(double(chunked)) < comm_.max(double(direct));
        }
        if (take)
        {
            L_.chunked = true;
            L_.chunks = std::move(X);
            L_.ownInView = ownToView_;
            dropDirectExchange();
        }
        if (mode_ == params::exchangeMode::chunked) return;
    }
    considerTree();
}

/// The tree (params::exchange tree, or automatic where exchangeCost()
/// finds it cheaper than the exchange chosen so far). Per own tile its key
/// and the nodes where this rank's partial omega is positive are gathered
/// (automatic: only when a lower bound of the tree's cost, from this rank's
/// nodes, is lower): the nodes of all ranks' tiles, which the tree sums.
template <int D>
void levelPlanner<D>::considerTree()
{
    static_assert(npt <= 64, "a tile's nodes in one 64-bit mask");
    std::vector<std::uint64_t> mine;   // key, nodes
    std::int64_t ownValues = 0;
    for (std::int64_t o = 0; o < nOwn_; ++o)
    {
        const std::uint64_t nodes = anyValue(ownMask_, o);
        if (!nodes) continue;
        mine.push_back(L_.view.keyOf(ownToView_[o]));
        mine.push_back(nodes);
        ownValues += nc_*std::int64_t(nodeCount(nodes));
    }
    const bool automatic = mode_ == params::exchangeMode::automatic;
    const double current = automatic ? currentExchangeCost() : 0;
    if (automatic && !(treeExchangeCost(std::int64_t(comm_.max(double(ownValues)))) < current)) return;
    std::vector<std::pair<std::uint64_t, std::uint64_t>> all;   // key, nodes of any rank
    for (const auto& r : comm_.allGather(mine))
        for (std::size_t i = 0; i + 1 < r.size(); i += 2) all.emplace_back(r[i], r[i + 1]);
    std::sort(all.begin(), all.end());
    std::vector<std::uint64_t> keys, nodes;
    std::vector<std::int64_t> start;
    std::int64_t values = 0;
    for (const auto& kn : all)
    {
        if (keys.empty() || keys.back() != kn.first)
        {
            keys.push_back(kn.first);
            nodes.push_back(0);
        }
        nodes.back() |= kn.second;
    }
    for (const std::uint64_t m : nodes)
    {
        start.push_back(values);
        values += nc_*std::int64_t(nodeCount(m));
    }
    if (automatic && !(treeExchangeCost(values) < current)) return;
    L_.tree = true;
    L_.chunked = false;
    L_.chunks = chunkExchange();
    dropDirectExchange();
    L_.treeValues = values;
    L_.ownInView = ownToView_;
    L_.treeStart.assign(L_.view.size(), -1);
    L_.treeNodes.assign(L_.view.size(), 0);
    for (std::int64_t id = 0; id < L_.view.size(); ++id)
    {
        const auto at = std::lower_bound(keys.begin(), keys.end(), L_.view.keyOf(id));
        if (at == keys.end() || *at != L_.view.keyOf(id)) continue;
        L_.treeStart[id] = start[at - keys.begin()];
        L_.treeNodes[id] = nodes[at - keys.begin()];
    }
}

/// The direct exchange's arrays emptied (the level exchanges otherwise)
template <int D>
void levelPlanner<D>::dropDirectExchange()
{
    L_.byGhostsTo.assign(nRanks_, 0);
    L_.byGhostsFrom.assign(nRanks_, 0);
    L_.nodesTo.assign(nRanks_, {});
    L_.nodesFrom.assign(nRanks_, {});
    L_.ghostsTo.assign(nRanks_, {});
    L_.ghostsFrom.assign(nRanks_, {});
    L_.ghostTiles.assign(nRanks_, {});
    L_.ghostStencils.assign(nRanks_, {});
    L_.ghostScales.assign(nRanks_, {});
    L_.receiveCounts.assign(nRanks_, 0);
}

/// Seconds of an apply's exchange in a latency-bandwidth model with
/// InfiniBand-class parameters (benchmarks/scalingModel.py's infiniband:
/// 2 us a round, 0.5 us a message, 10 GB/s): rounds plus the busiest
/// rank's messages and bytes received. Collective.
template <int D>
double levelPlanner<D>::exchangeCost(int rounds, std::int64_t messages, std::int64_t bytes) const
{
    const double alpha = 2e-6, overhead = 0.5e-6, beta = 10e9;
    return rounds*alpha + comm_.max(double(messages)*overhead + double(bytes)/beta);
}

/// exchangeCost of the level's exchange as chosen (direct or chunked). Collective.
template <int D>
double levelPlanner<D>::currentExchangeCost() const
{
    std::int64_t messages = 0, values = 0;
    for (int r = 0; r < nRanks_; ++r)
    {
        const std::size_t counts[3] = {L_.receiveCounts[r], L_.chunked ? L_.chunks.partialCounts[r] : 0,
                                       L_.chunked ? L_.chunks.fullCounts[r] : 0};
        for (const std::size_t c : counts)
        {
            messages += c > 0;
            values += std::int64_t(c);
        }
    }
    return exchangeCost(L_.chunked ? 2 : 1, messages, values*std::int64_t(sizeof(double)));
}

/// exchangeCost of the tree of n values. Collective.
template <int D>
double levelPlanner<D>::treeExchangeCost(std::int64_t n) const
{
    const treeTraffic t = treeTrafficOf(nRanks_, me_, std::size_t(n));
    return exchangeCost(t.rounds, t.messagesReceived, t.valuesReceived*std::int64_t(sizeof(double)));
}

template void levelPlanner<2>::chooseExchange();
template void levelPlanner<3>::chooseExchange();

} // namespace mba
