// bsplineMorph: OpenFOAM-free multilevel B-spline core (internal header)
// An element-wise sum of a vector over all ranks through a fixed binary tree
// of ranks (recursive halving, then recursive doubling: Rabenseifner's
// allreduce). A rank sends and receives one message a round, 2 log2(P)
// rounds (two more where P is not a power of two), whatever the number of
// ranks; it receives about twice the vector's size. Each value's sum is
// formed once, in the same tree for every value, and copied to every rank:
// identical on every rank, independent of the values.
#ifndef MBA_TREESUM_HPP
#define MBA_TREESUM_HPP

#include "communicator.hpp"

#include <cstddef>
#include <vector>

namespace mba {

/// One round of the tree as one rank takes part in it: v[sendBegin,
/// sendEnd) goes to rank sendTo and rank recvFrom's values arrive in
/// v[recvBegin, recvEnd), added when add (else stored); -1: no partner
struct treeRound
{
    int sendTo = -1, recvFrom = -1;
    std::size_t sendBegin = 0, sendEnd = 0, recvBegin = 0, recvEnd = 0;
    bool add = false;
};

/// The rounds of the sum of n values over P ranks as rank me takes part in
/// them: every rank has as many (empty ones where it waits)
std::vector<treeRound> treeRounds(int P, int me, std::size_t n);

/// What rank me sends and receives in the rounds of the sum of n values
/// over P ranks (messages: the non-empty ones)
struct treeTraffic
{
    int rounds = 0;
    std::int64_t messagesSent = 0, messagesReceived = 0, valuesSent = 0, valuesReceived = 0;
};
treeTraffic treeTrafficOf(int P, int me, std::size_t n);

/// v (the same size on every rank) summed over the ranks, in place, through
/// treeRounds (communicator::sendReceive); work is kept by the caller. Collective.
void treeSum(const communicator& comm, std::vector<double>& v, std::vector<double>& work);

} // namespace mba
#endif
