// bsplineMorph: OpenFOAM-free multilevel B-spline core (internal header)
// The chunked exchange of a level's partial sums (params::exchange): its
// layout, made in the level's plan from what the plan knows of the tiles'
// contributors and readers, and used by every apply (levelApply.cpp).
#ifndef MBA_CHUNKEXCHANGE_HPP
#define MBA_CHUNKEXCHANGE_HPP

#include "hugePages.hpp"
#include "communicator.hpp"
#include "lattice.hpp"

#include <cstdint>
#include <vector>

namespace mba {

/// A run of nodes of a view tile: nodes x nc values from phi[(tile*npt + node0)*nc]
struct nodeRun
{
    std::int64_t tile;
    std::int32_t node0, nodes;
};

/// A contributor's partial sums on an owned chunk: from this rank (offset
/// -1: in phi, the whole chunk) or from another (its values at offset in
/// that rank's round-1 message, on the node runs termRuns[runsBegin,
/// runsEnd), where its partial omega is positive)
struct chunkTerm
{
    std::int32_t rank;
    std::int64_t offset;
    std::int32_t runsBegin, runsEnd;
};

/// The chunked exchange of a level (params::exchange). Each node of a tile with
/// contributors C (sorted ranks) belongs to one of the contributors whose
/// partial omega is positive there (nodeOwners). A chunk is a run of a tile's
/// nodes with the same owner. Round 1: every contributor sends its partial sums
/// on the chunks of its tiles that others own to their owners; each owner sums
/// its chunks in rank order and divides them by omega. Round 2: each owner
/// sends its chunks' phi to every other rank that reads the tile, at the nodes
/// that rank reads, which it stores: a rank clears and divides only what it
/// owns. Only nodes with omega > 0 travel (a contributor's partial omega in
/// round 1, the sum in round 2; both sides know them from the plan). Both sides
/// list a message's runs in tile-key order, chunks and nodes in order. A node
/// costs the ranks together (|C_n| - 1) + (|R_n| - 1) values, C_n the ranks
/// whose points weigh it and R_n those that read it.
struct chunkExchange
{
    std::vector<std::vector<nodeRun>> partialTo; ///< per rank: own partial sums it sums (round 1)
    std::vector<nodeRun> owned;                  ///< the chunks this rank sums
    std::vector<std::int64_t> termsBegin;        ///< per owned chunk: its terms in terms (CSR, owned.size() + 1)
    std::vector<chunkTerm> terms;                ///< per owned chunk, its contributors in rank order
    std::vector<nodeRun> termRuns;               ///< the terms' node runs
    std::vector<std::vector<nodeRun>> fullTo;    ///< per rank: summed chunks sent to it (round 2)
    std::vector<std::vector<nodeRun>> fullFrom;  ///< per rank: summed chunks it sends here
    std::vector<std::size_t> partialCounts;      ///< per rank: values it sends here in round 1
    std::vector<std::size_t> fullCounts;         ///< per rank: values it sends here in round 2
};

/// Values (nc a node) of runs
std::int64_t runValues(const std::vector<nodeRun>& runs, int nc);

/// The contributor (an index into the tile's m, ranks C) that sums each of a
/// tile's npt nodes (planChunks), into owner: one of those whose partial omega
/// is positive there (per node, a set of m bits in `words` words of reach). The
/// nodes that the same contributors reach are split among them in contiguous
/// shares in node order, rotated by the tile's key. Summing a node that s
/// contributors reach costs its owner s - 2 values more than the others (s - 1
/// partial sums in, the sum not received): from s = 3 the shares shrink with
/// the rank's load (loads, per rank), by weight M + M/16 + 1 - load, M the
/// largest load among the s. A node that none reaches goes with the node before
/// it (or the first that one reaches). Every rank that holds the tile knows all
/// contributors' partial omega on it, hence the same owners.
void nodeOwners(const int* C, std::int64_t m, int npt, std::uint64_t key, const std::vector<std::uint64_t>& reach,
                std::size_t words, const std::vector<std::int64_t>& loads, std::vector<int>& owner);

/// What a level's plan knows that its chunks are made from (tiles as view ids)
template <int D>
struct chunkSources
{
    int nRanks, me, nc, omegaPerNode;
    const tileLayout<D>& view;
    const std::vector<std::int64_t>& ownToView;              ///< own tile id -> view id
    const std::vector<std::vector<std::int64_t>>& tilesFrom; ///< per rank: the view tiles it contributes to
    const std::vector<std::vector<std::int64_t>>& tilesTo;   ///< per rank: the own tiles it reads
    const std::vector<std::vector<std::uint64_t>>& readTo;   ///< per rank: the nodes it reads of each (bit n: node n)
    const std::vector<std::uint64_t>& read;                  ///< per view tile: the nodes this rank reads
    /// per own tile and omega value: the nodes where this rank's partial omega is > 0 (bit n: node n)
    const std::vector<std::uint64_t>& ownMask;
    /// per rank: the same on tilesFrom's tiles
    const std::vector<std::vector<std::uint64_t>>& maskFrom;
    /// per view tile and omega value: the nodes where omega is > 0 (bit n: node n)
    const std::vector<std::uint64_t>& summedNodes;
    /// the ranks (planChunks gathers each rank's load on the level through it)
    const communicator& comm;
};

/// The chunked exchange. Every rank that holds a tile in its view reads it
/// and asked every contributor for it: each knows the tile's contributors,
/// hence every chunk's owner, and each owner knows the tile's readers (the
/// ranks that asked it).
template <int D>
chunkExchange planChunks(const chunkSources<D>& in);

} // namespace mba
#endif
