// bsplineMorph: OpenFOAM-free multilevel B-spline core
// Evaluation points handed from ranks that work more than the mean to ranks
// that work less.
//
// The fit's work follows the control points, which lie on the walls, while
// every rank evaluates the points of its own cells: with box-shaped ranks
// (hierarchical, scotch) the ranks at the walls fit and evaluate, the ranks
// inside only evaluate, and a step waits for the busiest. A rank's
// evaluation points need no particular rank: the lattices that a plan
// builds for them are the same on every rank, so a point's value does not
// depend on where it is evaluated, but for round-off. This hands evaluation points from each
// rank that works more than the mean to the nearest ranks that work less
// (their points nearest the receiving rank's), so that every rank works
// about the mean (as counted: workOf()), and returns the values every step:
// 8 bytes per moved point and component. A plan then evaluates points() instead of the rank's
// own points, and restore() puts the values back in the own points' order.
#ifndef MBA_EVALUATIONBALANCE_HPP
#define MBA_EVALUATIONBALANCE_HPP

#include "communicator.hpp"
#include "geometry.hpp"

#include <cstdint>
#include <vector>

namespace mba {

/// Points a rank hands to another
struct evaluationMove
{
    int from = 0, to = 0;
    std::int64_t count = 0;
};

/// What each rank reports for the balance: its work (in evaluation points'
/// worth: workOf()), its evaluation points and their bounding box
template <int D>
struct rankWork
{
    double work = 0;
    std::int64_t points = 0;
    box<D> bounds = box<D>::empty();
};

/// The work of a step of a rank, counted in evaluation points' worth: each
/// evaluation point one, each control point controlLevelCost a level it is
/// fitted on. Counted rather than timed, so that the same case moves the
/// same points in every run (a point's value may differ at round-off from
/// rank to rank: a rank's evaluation folds the coarse levels into one
/// lattice whose level follows its points)
constexpr double controlLevelCost = 4;
inline double workOf(std::int64_t nControl, int levels, std::int64_t nEvaluation)
{
    return controlLevelCost*double(nControl)*levels + double(nEvaluation);
}

/// The moves that bring every rank's work near the mean, the same on every
/// rank: none unless the busiest works more than threshold times the mean.
/// Ranks above the mean, the busiest first (ties: the lower rank), hand
/// points to the ranks below it whose boxes' centres are nearest its own
/// (ties: the lower rank), each up to the mean
template <int D>
std::vector<evaluationMove> balanceMoves(const std::vector<rankWork<D>>& ranks, double threshold);

template <int D>
class evaluationBalance
{
    const communicator& comm_;
    std::size_t nOwn_ = 0;
    std::vector<std::size_t> kept_;                 ///< own points evaluated here (ascending)
    std::vector<std::vector<std::size_t>> sent_;    ///< per rank: own points it evaluates (ascending)
    std::vector<std::size_t> receivedCount_;        ///< per rank: its points evaluated here
    std::vector<double> xyz_;                       ///< points(): kept, then received in rank order
    std::vector<evaluationMove> moves_;
    double imbalance_ = 1;

public:
    /// Collective. points: this rank's evaluation points (copied); work:
    /// its work (workOf() of its control points, the levels and points).
    /// threshold >= 1.
    evaluationBalance(const communicator& comm, pointsView<D> points, double work, double threshold);
    /// The plan keeps the communicator: a temporary one would dangle
    evaluationBalance(const communicator&&, pointsView<D>, double, double) = delete;

    /// The moves of all ranks (empty: every rank evaluates its own points)
    const std::vector<evaluationMove>& moves() const { return moves_; }
    /// The busiest rank's work over the mean, as reported
    double imbalance() const { return imbalance_; }
    /// The points this rank evaluates: its own that it keeps, then those it
    /// received, by rank
    pointsView<D> points() const { return pointsView<D>(xyz_.data(), xyz_.size()/D); }
    std::size_t nSent() const { return nOwn_ - kept_.size(); }
    std::size_t nReceived() const { return points().size - kept_.size(); }

    /// The values at points() (point x component) to those at this rank's
    /// own points, the moved ones from the ranks that evaluated them.
    /// Collective.
    void restore(const std::vector<double>& evaluated, int nComponents, std::vector<double>& own) const;
};

} // namespace mba
#endif
