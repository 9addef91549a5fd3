// The tree of the sum over ranks: the rounds, then the sum through them.
#include "treeSum.hpp"

#include <algorithm>

namespace mba {

std::vector<treeRound> treeRounds(int P, int me, std::size_t n)
{
    std::vector<treeRound> rounds;
    if (P < 2) return rounds;
    int p2 = 1;
    while (2*p2 <= P) p2 *= 2;
    const int extra = P - p2;   // ranks p2 + i first hand their values to rank i, and get the sums back last
    const bool inTree = me < p2;
    if (extra > 0)
    {
        treeRound r;
        if (me >= p2) { r.sendTo = me - p2; r.sendEnd = n; }
        if (me < extra) { r.recvFrom = me + p2; r.recvEnd = n; r.add = true; }
        rounds.push_back(r);
    }
    // recursive halving: with the partner across bit m, keep one half of the
    // range, receive the partner's values there and add them
    struct range { std::size_t lo, hi; int partner; bool upper; };
    std::vector<range> halvings;
    std::size_t lo = 0, hi = n;
    for (int m = p2/2; m >= 1; m /= 2)
    {
        treeRound r;
        if (inTree)
        {
            const std::size_t mid = lo + (hi - lo)/2;
            const bool upper = (me & m) != 0;
            halvings.push_back(range{lo, hi, me ^ m, upper});
            r.sendTo = r.recvFrom = me ^ m;
            r.add = true;
            if (upper) { r.sendBegin = lo; r.sendEnd = mid; r.recvBegin = mid; r.recvEnd = hi; lo = mid; }
            else { r.sendBegin = mid; r.sendEnd = hi; r.recvBegin = lo; r.recvEnd = mid; hi = mid; }
        }
        rounds.push_back(r);
    }
    // recursive doubling: the halvings undone in reverse, each rank sending
    // the summed half it kept and storing its partner's
    for (int m = 1; m < p2; m *= 2)
    {
        treeRound r;
        if (inTree)
        {
            const range& h = halvings.back();
            const std::size_t mid = h.lo + (h.hi - h.lo)/2;
            r.sendTo = r.recvFrom = h.partner;
            if (h.upper) { r.sendBegin = mid; r.sendEnd = h.hi; r.recvBegin = h.lo; r.recvEnd = mid; }
            else { r.sendBegin = h.lo; r.sendEnd = mid; r.recvBegin = mid; r.recvEnd = h.hi; }
            halvings.pop_back();
        }
        rounds.push_back(r);
    }
    if (extra > 0)
    {
        treeRound r;
        if (me < extra) { r.sendTo = me + p2; r.sendEnd = n; }
        if (me >= p2) { r.recvFrom = me - p2; r.recvEnd = n; }
        rounds.push_back(r);
    }
    return rounds;
}

treeTraffic treeTrafficOf(int P, int me, std::size_t n)
{
    treeTraffic t;
    for (const treeRound& r : treeRounds(P, me, n))
    {
        ++t.rounds;
        t.messagesSent += r.sendEnd > r.sendBegin;
        t.messagesReceived += r.recvEnd > r.recvBegin;
        t.valuesSent += std::int64_t(r.sendEnd - r.sendBegin);
        t.valuesReceived += std::int64_t(r.recvEnd - r.recvBegin);
    }
    return t;
}

void treeSum(const communicator& comm, std::vector<double>& v, std::vector<double>& work)
{
    for (const treeRound& r : treeRounds(comm.size(), comm.rank(), v.size()))
    {
        work.resize(r.recvEnd - r.recvBegin);
        comm.sendReceive(r.sendTo, v.data() + r.sendBegin, r.sendEnd - r.sendBegin, r.recvFrom, work.data(),
                         work.size());
        double* to = v.data() + r.recvBegin;
        if (r.add) for (std::size_t j = 0; j < work.size(); ++j) to[j] += work[j];
        else std::copy(work.begin(), work.end(), to);
    }
}

} // namespace mba
