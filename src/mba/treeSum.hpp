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

/// One round of the tree as one rank takes part in it: the whole vector
/// goes to the ranks to[] and the vectors of the ranks from[] arrive, added
/// in order when add (else stored); -1: no partner
struct treeRound
{
    int to[2] = {-1, -1}, from[2] = {-1, -1};
    bool add = false;
};

/// The rounds of the sum over P ranks as rank me takes part in them: every
/// rank has as many (empty ones where it waits)
std::vector<treeRound> treeRounds(int P, int me);

/// What rank me sends and receives in the rounds of the sum of n values
/// over P ranks (messages: the non-empty ones)
struct treeTraffic
{
    int rounds = 0;
    std::int64_t messagesSent = 0, messagesReceived = 0, valuesSent = 0, valuesReceived = 0;
};
treeTraffic treeTrafficOf(int P, int me, std::size_t n);

/// v (the same size on every rank) summed over the ranks, in place, through
/// treeRounds (communicator::exchange); send and recv are kept by the
/// caller. Collective.
void treeSum(const communicator& comm, std::vector<double>& v, std::vector<std::vector<double>>& send,
             std::vector<std::vector<double>>& recv);

} // namespace mba
#endif
