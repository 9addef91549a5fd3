// The chunked exchange's layout: the tiles' contributors and readers, then
// the chunks, their owners and the node runs that travel.
#include "chunkExchange.hpp"

#include <algorithm>
#include <functional>

namespace mba {

std::int64_t runValues(const std::vector<nodeRun>& runs, int nc)
{
    std::int64_t n = 0;
    for (const nodeRun& r : runs) n += std::int64_t(r.nodes)*nc;
    return n;
}

namespace {

/// Per view tile (CSR): its contributors in rank order, with where their
/// partial omega is (own id for this rank, else the position in what the
/// rank sent), and the readers of own tiles; the tiles with contributors
/// in key order (the order both sides of every message list them in)
struct tileTable
{
    std::vector<std::int64_t> cBegin, rBegin;
    std::vector<int> contributors, readers;
    std::vector<std::uint64_t> readerNodes;   ///< the nodes each reader reads
    std::vector<std::int64_t> where;
    std::vector<std::int64_t> byKey;
};

template <int D>
tileTable makeTileTable(const chunkSources<D>& in)
{
    const std::int64_t nView = in.view.size();
    tileTable T;
    T.cBegin.assign(nView + 1, 0);
    T.rBegin.assign(nView + 1, 0);
    auto forContributors = [&](const std::function<void(std::int64_t, int, std::int64_t)>& f) {
        for (int r = 0; r < in.nRanks; ++r)
        {
            if (r == in.me)
                for (std::size_t o = 0; o < in.ownToView.size(); ++o) f(in.ownToView[o], r, std::int64_t(o));
            else
                for (std::size_t t = 0; t < in.tilesFrom[r].size(); ++t) f(in.tilesFrom[r][t], r, std::int64_t(t));
        }
    };
    auto forReaders = [&](const std::function<void(std::int64_t, int, std::uint64_t)>& f) {
        for (int r = 0; r < in.nRanks; ++r)
            for (std::size_t t = 0; t < in.tilesTo[r].size(); ++t) f(in.tilesTo[r][t], r, in.readTo[r][t]);
    };
    forContributors([&](std::int64_t id, int, std::int64_t) { ++T.cBegin[id + 1]; });
    forReaders([&](std::int64_t id, int, std::uint64_t) { ++T.rBegin[id + 1]; });
    for (std::int64_t id = 0; id < nView; ++id)
    {
        T.cBegin[id + 1] += T.cBegin[id];
        T.rBegin[id + 1] += T.rBegin[id];
    }
    T.contributors.resize(T.cBegin[nView]);
    T.where.resize(T.cBegin[nView]);
    T.readers.resize(T.rBegin[nView]);
    T.readerNodes.resize(T.rBegin[nView]);
    std::vector<std::int64_t> cAt(T.cBegin.begin(), T.cBegin.end() - 1), rAt(T.rBegin.begin(), T.rBegin.end() - 1);
    forContributors([&](std::int64_t id, int r, std::int64_t w) {
        T.where[cAt[id]] = w;
        T.contributors[cAt[id]++] = r;
    });
    forReaders([&](std::int64_t id, int r, std::uint64_t nodes) {
        T.readerNodes[rAt[id]] = nodes;
        T.readers[rAt[id]++] = r;
    });
    for (std::int64_t id = 0; id < nView; ++id) if (T.cBegin[id + 1] > T.cBegin[id]) T.byKey.push_back(id);
    std::sort(T.byKey.begin(), T.byKey.end(), [&](std::int64_t a, std::int64_t b) {
        return in.view.keyOf(a) < in.view.keyOf(b);
    });
    return T;
}

/// The runs of the nodes [n0, n0 + nodes) of tile id where on(n), appended to out
void maskedRuns(std::int64_t id, int n0, int nodes, const std::function<bool(int)>& on, std::vector<nodeRun>& out)
{
    for (int n = n0; n < n0 + nodes;)
    {
        if (!on(n)) { ++n; continue; }
        int e = n + 1;
        while (e < n0 + nodes && on(e)) ++e;
        out.push_back(nodeRun{id, std::int32_t(n), std::int32_t(e - n)});
        n = e;
    }
}

/// Whether contributor c is in a node's set of contributors (bits, 64 a word)
inline bool inSet(const std::uint64_t* set, std::int64_t c)
{
    return (set[c/64] >> (c % 64) & 1) != 0;
}

} // namespace

void nodeOwners(const int* C, std::int64_t m, int npt, std::uint64_t key, const std::vector<std::uint64_t>& reach,
                std::size_t words, const std::vector<std::int64_t>& loads, std::vector<int>& owner)
{
    owner.assign(npt, -1);
    auto set = [&](int n) { return reach.begin() + n*words; };
    std::vector<int> order(npt), members;
    std::vector<std::int64_t> upTo;   // per member in turn: the summed weights up to it
    for (int n = 0; n < npt; ++n) order[n] = n;
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
        return std::lexicographical_compare(set(a), set(a) + words, set(b), set(b) + words);
    });
    for (int g = 0; g < npt;)
    {
        int e = g + 1;
        while (e < npt && std::equal(set(order[g]), set(order[g]) + words, set(order[e]))) ++e;
        members.clear();
        for (std::int64_t c = 0; c < m; ++c)
            if (inSet(&reach[std::size_t(order[g])*words], c)) members.push_back(int(c));
        const std::int64_t s = std::int64_t(members.size()), size = e - g;
        if (s == 0) { g = e; continue; }
        std::rotate(members.begin(), members.begin() + std::ptrdiff_t(key % std::uint64_t(s)), members.end());
        std::int64_t M = 0;
        for (const int c : members) M = std::max(M, loads[std::size_t(C[c])]);
        upTo.assign(1, 0);
        for (const int c : members) upTo.push_back(upTo.back() + (s < 3 ? 1 : M + M/16 + 1 - loads[std::size_t(C[c])]));
        // node i of the group to the member whose weights hold its middle
        std::size_t j = 0;
        for (int i = g; i < e; ++i)
        {
            while (j + 1 < members.size() && (2*(i - g) + 1)*upTo.back() >= 2*size*upTo[j + 1]) ++j;
            owner[order[i]] = members[j];
        }
        g = e;
    }
    int first = 0;
    while (first < npt && owner[first] < 0) ++first;
    for (int n = 0; n < npt; ++n)
        if (owner[n] < 0) owner[n] = n < first ? (first < npt ? owner[first] : 0) : owner[n - 1];
}

template <int D>
chunkExchange planChunks(const chunkSources<D>& in)
{
    constexpr int npt = tileLayout<D>::nodesPerTile;
    const tileTable T = makeTileTable(in);
    // Only nodes with omega > 0 carry values: of a contributor's partial
    // sums where its partial omega is (each side knows it: the plan sent
    // it), of the sums where the sum of omega is (every reader has it)
    const int per = in.omegaPerNode;
    // the nodes of tile w (own id, or place in tilesFrom) where rank r's partial omega is > 0
    auto partialNodes = [&](int r, std::int64_t w) {
        return anyValue(r == in.me ? in.ownMask : in.maskFrom[r], w, per);
    };
    chunkExchange X;
    X.partialTo.assign(in.nRanks, {});
    X.fullTo.assign(in.nRanks, {});
    X.fullFrom.assign(in.nRanks, {});
    X.termsBegin.push_back(0);
    std::vector<std::int64_t> offset(in.nRanks, 0);   // values from each rank in round 1 so far
    std::vector<nodeRun> runs;
    std::vector<std::uint64_t> reach;
    std::vector<int> by;   // per node of a tile: the contributor that sums it
    // per node of tile id: the contributors whose partial omega is positive
    const auto tileReach = [&](std::int64_t id) {
        const int* C = &T.contributors[T.cBegin[id]];
        const std::int64_t* W = &T.where[T.cBegin[id]];
        const std::int64_t m = T.cBegin[id + 1] - T.cBegin[id];
        const std::size_t words = std::size_t((m + 63)/64);
        reach.assign(npt*words, 0);
        for (std::int64_t c = 0; c < m; ++c)
        {
            const std::uint64_t nodes = partialNodes(C[c], W[c]);
            for (int n = 0; n < npt; ++n)
                if (nodes >> n & 1) reach[n*words + c/64] |= std::uint64_t(1) << (c % 64);
        }
        return words;
    };
    // this rank's load, which no owner changes: the nodes it reads that
    // another rank's points weigh
    std::int64_t load = 0;
    for (const std::int64_t id : T.byKey)
    {
        if (!in.read[id]) continue;
        const int* C = &T.contributors[T.cBegin[id]];
        const std::int64_t m = T.cBegin[id + 1] - T.cBegin[id];
        const std::size_t words = tileReach(id);
        for (int n = 0; n < npt; ++n)
        {
            if (!(in.read[id] >> n & 1)) continue;
            bool other = false;
            for (std::int64_t c = 0; c < m && !other; ++c)
                other = C[c] != in.me && inSet(&reach[n*words], c);
            load += other;
        }
    }
    // every rank's load (collective: every rank plans its chunks)
    const std::vector<std::int64_t> loads = in.comm.allGatherFixed(std::vector<std::int64_t>{load*in.nc});
    for (const std::int64_t id : T.byKey)
    {
        const int* C = &T.contributors[T.cBegin[id]];
        const std::int64_t m = T.cBegin[id + 1] - T.cBegin[id];
        const std::int64_t self = std::find(C, C + m, in.me) - C;   // m: not a contributor
        const std::uint64_t summedHere = anyValue(in.summedNodes, id, per);
        const auto summed = [&](int n) { return (summedHere >> n & 1) != 0; };
        const auto readHere = [&](int n) { return (in.read[id] >> n & 1) != 0 && summed(n); };
        std::size_t words = 0;
        if (m == 1) by.assign(npt, 0);
        else
        {
            words = tileReach(id);
            nodeOwners(C, m, npt, in.view.keyOf(id), reach, words, loads, by);
        }
        // whether contributor c's partial omega is positive at node n (asked
        // only where m > 1: a tile's sole contributor sums it all and sends
        // no partial sum)
        const auto weighs = [&](std::int64_t c, int n) { return inSet(&reach[n*words], c); };
        for (int n0 = 0, e = 1; n0 < npt; n0 = e++)
        {
            while (e < npt && by[e] == by[n0]) ++e;
            const int nodes = e - n0, owner = C[by[n0]];
            if (owner != in.me)
            {
                if (self < m)
                    maskedRuns(id, n0, nodes, [&](int n) { return weighs(self, n); }, X.partialTo[owner]);
                maskedRuns(id, n0, nodes, readHere, X.fullFrom[owner]);
                continue;
            }
            X.owned.push_back(nodeRun{id, std::int32_t(n0), std::int32_t(nodes)});
            for (std::int64_t c = 0; c < m; ++c)
            {
                chunkTerm term{C[c], -1, std::int32_t(X.termRuns.size()), std::int32_t(X.termRuns.size())};
                if (C[c] != in.me)
                {
                    runs.clear();
                    maskedRuns(id, n0, nodes, [&](int n) { return weighs(c, n); }, runs);
                    term.offset = offset[C[c]];
                    for (const nodeRun& r : runs)
                    {
                        X.termRuns.push_back(r);
                        offset[C[c]] += std::int64_t(r.nodes)*in.nc;
                    }
                    term.runsEnd = std::int32_t(X.termRuns.size());
                }
                X.terms.push_back(term);
            }
            X.termsBegin.push_back(std::int64_t(X.terms.size()));
            for (std::int64_t q = T.rBegin[id]; q < T.rBegin[id + 1]; ++q)
                maskedRuns(id, n0, nodes, [&](int n) { return (T.readerNodes[q] >> n & 1) != 0 && summed(n); },
                           X.fullTo[T.readers[q]]);
        }
    }
    X.partialCounts.assign(offset.begin(), offset.end());
    for (int r = 0; r < in.nRanks; ++r) X.fullCounts.push_back(std::size_t(runValues(X.fullFrom[r], in.nc)));
    return X;
}

template chunkExchange planChunks<2>(const chunkSources<2>&);
template chunkExchange planChunks<3>(const chunkSources<3>&);

} // namespace mba
