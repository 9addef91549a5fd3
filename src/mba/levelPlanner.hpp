// bsplineMorph: OpenFOAM-free multilevel B-spline core (internal header)
// The planner of one level (levelPlan.cpp: the steps of run(); the points
// alone at their nodes: levelPlanLone.cpp; the choice of the level's
// exchange, chooseExchange() and what it uses: levelPlanExchange.cpp).
#ifndef MBA_LEVELPLANNER_HPP
#define MBA_LEVELPLANNER_HPP

#include "levelPlan.hpp"

#include <cstdint>
#include <functional>
#include <vector>

namespace mba {

/// The planning of one level, step after step (run() in order)
template <int D>
class levelPlanner
{
    static constexpr int npt = levelPlan<D>::npt;

    const communicator& comm_;          ///< the ranks
    const domain<D>& dom_;              ///< the lattices' domain
    const controlPoints<D>& ctrl_;      ///< this rank's control points
    const queryClusters<D>& clusters_;  ///< this rank's query points (parallel only)
    const int bucketTiles_;             ///< target tiles per bucket (params::bucketTiles)
    const params::exchangeMode mode_;   ///< how the partial sums meet (params::exchange)
    const int nRanks_, me_;             ///< the communicator's size and this rank
    const int nc_, omegaPerNode_;       ///< values a point, omega values a node (as ctrl_'s)

    levelPlan<D> L_;                    ///< the plan being made
    index<D> nodes_;                    ///< the level's nodes per direction
    std::int64_t nOwn_ = 0;             ///< own tiles
    std::vector<stencilTiles<D>> ownIds_; ///< the own points' stencil tiles in the own layout, in order
    /// per own tile and omega value: the nodes where this rank's partial
    /// omega is > 0 (bit n: node n), where a weight w of a point it holds
    /// has w^2 > 0
    std::vector<std::uint64_t> ownMask_;
    /// the same where two or more of its points' w^2 are > 0
    std::vector<std::uint64_t> ownMulti_;
    /// per view tile and omega value: the nodes where two or more points
    /// of all ranks have w^2 > 0 (as coefficientNodes where one or more
    /// have), until the lone points are found
    std::vector<std::uint64_t> multiNodes_;
    /// omega, not inverted, at the slots that formOmega() was given: where
    /// aloneAtNodes reads it (omegaSlot_), then on the stored tiles; in
    /// answerRequests this rank's partial omega on the tiles asked for
    hugeVector<double> omega_;
    /// while the lone points are found: per view tile its omega's place in
    /// omega_ (-1: none), on the tiles where two or more points' w^2 are > 0
    /// (on a dense view every tile: its omega is kept)
    std::vector<std::int32_t> omegaSlot_;
    std::vector<std::vector<std::uint64_t>> keysFrom_; ///< per rank: keys of the tiles it sends here
    std::vector<std::vector<double>> omegaFrom_;       ///< per rank: their partial omega
    /// per rank: per tile it sends here and omega value, the nodes where its
    /// partial omega is > 0 (bit n: node n)
    std::vector<std::vector<std::uint64_t>> maskFrom_;
    std::vector<std::int64_t> ownToView_;              ///< own tile id -> view id (parallel)
    /// per rank: the tiles this rank asked it for, each key followed by the
    /// nodes this rank reads there (bit n: node n)
    std::vector<std::vector<std::uint64_t>> requests_;
    /// per rank: the nodes it reads of each tile in tilesTo
    std::vector<std::vector<std::uint64_t>> asked_;
    /// per view tile: the lone points' nodes (bit n: node n; empty: no lone point)
    std::vector<std::uint64_t> loneNodes_;

    void startLevel(int k);
    void ownTiles();
    void findAskedTiles(const std::vector<std::vector<std::uint64_t>>& wanted);
    bool readByEvaluation(const std::function<bool(const levelPlan<D>&)>& isRead);
    bool viewIsDense() const;
    template <class Slot>
    void ownOmega(const std::vector<stencilTiles<D>>& tiles, std::int64_t nSlots, Slot slot);
    template <class Slot>
    void formOmega(std::int64_t nSlots, Slot slot);
    void omegaWhereShared();
    /// omega at view tile id's nodes (not inverted), where aloneAtNodes reads it
    const double* omegaAt(std::int64_t id) const { return omega_.data() + omegaSlot_[id]*npt*omegaPerNode_; }
    std::vector<std::vector<std::int64_t>> bucketDirectory();
    std::vector<indexBox<D>> clusterTileBoxes(indexBox<D>& all) const;
    std::vector<std::vector<std::uint64_t>> tileRequests(const std::vector<std::vector<std::int64_t>>& directory) const;
    void answerRequests();
    std::vector<std::vector<double>> chooseGhosts();
    void assembleView();
    void findControlTiles();
    bool aloneAtNodes(std::size_t q, const stencil<D>& st, bool freeZero) const;
    void testSeparation();
    void findLonePoints();
    void storeLoneTilesLast();
    void indexLonePoints();
    void findGhostTiles();
    void chooseExchange();
    /// The nodes of tile id set in any of its omega values' masks (masks:
    /// omegaPerNode_ a tile, bit n: node n); of ownMask_, where this rank's
    /// partial omega is > 0: where its partial sums can be other than 0
    std::uint64_t anyValue(const std::vector<std::uint64_t>& masks, std::int64_t id) const
    {
        return mba::anyValue(masks, id, omegaPerNode_);
    }
    void findCoefficientNodes();
    void findCoefficientRuns();
    void considerTree();
    void dropDirectExchange();
    double exchangeCost(int rounds, std::int64_t messages, std::int64_t bytes) const;
    double currentExchangeCost() const;
    double treeExchangeCost(std::int64_t n) const;
    void keepOmega();
    void fillStats();

public:
    levelPlanner(const communicator& comm, const domain<D>& dom, const controlPoints<D>& ctrl,
                 const queryClusters<D>& clusters, int bucketTiles, params::exchangeMode mode)
    :
        comm_(comm), dom_(dom), ctrl_(ctrl), clusters_(clusters), bucketTiles_(bucketTiles), mode_(mode),
        nRanks_(comm.size()), me_(comm.rank()), nc_(ctrl.nComponents), omegaPerNode_(ctrl.omegaPerNode)
    {}

    /// planLevel
    levelPlan<D> run(int k, const std::function<bool(const levelPlan<D>&)>& isRead);
};

} // namespace mba
#endif
