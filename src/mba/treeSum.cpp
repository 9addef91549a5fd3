// The tree of the sum over ranks: the rounds, then the sum through them.
#include "treeSum.hpp"

#include <algorithm>

namespace mba {

namespace {

/// Depth of rank r in the tree (the root 0 at depth 0)
int depthOf(int r)
{
    int d = 0;
    while (r > 0) { r = (r - 1)/2; ++d; }
    return d;
}

} // namespace

std::vector<treeRound> treeRounds(int P, int me)
{
    std::vector<treeRound> rounds;
    if (P < 2) return rounds;
    const int D = depthOf(P - 1), mine = depthOf(me);
    const int children[2] = {2*me + 1, 2*me + 2};
    // the sums: the ranks at depth D - t send theirs (their subtree's) to
    // their parents, which add them to their own, the first child's first
    for (int t = 0; t < D; ++t)
    {
        treeRound r;
        r.add = true;
        if (mine == D - t) r.to[0] = (me - 1)/2;
        if (mine == D - t - 1)
            for (int c = 0; c < 2; ++c) if (children[c] < P) r.from[c] = children[c];
        rounds.push_back(r);
    }
    // the total: from the root down, each rank's copied from its parent
    for (int t = 0; t < D; ++t)
    {
        treeRound r;
        if (mine == t)
            for (int c = 0; c < 2; ++c) if (children[c] < P) r.to[c] = children[c];
        if (mine == t + 1) r.from[0] = (me - 1)/2;
        rounds.push_back(r);
    }
    return rounds;
}

treeTraffic treeTrafficOf(int P, int me, std::size_t n)
{
    treeTraffic t;
    for (const treeRound& r : treeRounds(P, me))
    {
        ++t.rounds;
        for (int c = 0; c < 2; ++c)
        {
            t.messagesSent += r.to[c] >= 0 && n > 0;
            t.messagesReceived += r.from[c] >= 0 && n > 0;
            t.valuesSent += r.to[c] >= 0 ? std::int64_t(n) : 0;
            t.valuesReceived += r.from[c] >= 0 ? std::int64_t(n) : 0;
        }
    }
    return t;
}

void treeSum(const communicator& comm, std::vector<double>& v, std::vector<std::vector<double>>& send,
             std::vector<std::vector<double>>& recv)
{
    const int P = comm.size();
    send.resize(P);
    recv.resize(P);
    for (const treeRound& r : treeRounds(P, comm.rank()))
    {
        for (auto& s : send) s.clear();
        for (auto& s : recv) s.clear();
        for (int c = 0; c < 2; ++c)
        {
            if (r.to[c] >= 0) send[r.to[c]] = v;
            if (r.from[c] >= 0) recv[r.from[c]].resize(v.size());
        }
        comm.exchange(send, recv);
        for (int c = 0; c < 2; ++c)
        {
            if (r.from[c] < 0) continue;
            const std::vector<double>& got = recv[r.from[c]];
            if (r.add) for (std::size_t j = 0; j < v.size(); ++j) v[j] += got[j];
            else std::copy(got.begin(), got.end(), v.begin());
        }
    }
}

} // namespace mba
