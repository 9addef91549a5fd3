// bsplineMorph: OpenFOAM-free multilevel B-spline core (internal header)
// The evaluation accelerator, rebuilt after every fit: the coarse levels are
// refined by B-spline subdivision (subdivision.hpp: exact) to one level and
// summed there, with the affine approximation (which cubic B-splines
// reproduce exactly from its node values), into one plain, untiled lattice
// over the nodes that the planned evaluation points' stencils touch (the
// flat lattice: plainLattice.hpp), so that most points cost one contiguous
// stencil. The finer levels are added only at the points where they have
// coefficients, found once per set of planned levels.
#ifndef MBA_FLATEVALUATOR_HPP
#define MBA_FLATEVALUATOR_HPP

#include "affine.hpp"
#include "levelPlan.hpp"
#include "trendLattice.hpp"

#include <utility>

namespace mba {

/// The most nodes a flat lattice of a rank with nEval evaluation points
/// has: one a point up to 65536 (1.5 MB at three values a node, about what
/// one core's caches hold), one per 8 points where that is more, and at
/// least 4096. A larger lattice, read from main memory and refined there in
/// every fit, costs more than the finer levels that the points near the
/// control points then add one by one (BENCHMARKS.md, "The flat lattice's
/// size")
double flatNodeBudget(std::size_t nEval);

template <int D>
class flatEvaluator
{
    const evaluationPoints<D>& eval_;   ///< this rank's evaluation points
    const controlPoints<D>& ctrl_;      ///< this rank's control points (for the omega values a node holds)
    const domain<D>& dom_;              ///< the lattices' domain
    const int nc_;                      ///< values a point

    /// The finest level folded into the flat lattice: the finest whose box
    /// has at most flatNodeBudget(evaluation points) nodes; -1: none
    /// (evaluation then sums the levels' tiles point by point)
    int flatLevel_ = -1;
    indexBox<D> flatBox_;               ///< the flat lattice's nodes (at level flatLevel_)
    hugeVector<double> flatPhi_;        ///< its coefficients, nc a node (kept: no new pages per fit)
    hugeVector<double> refineScratch_;  ///< the subdivision's second array (kept as well)
    /// The evaluation points (positions in the sweep's order, ascending)
    /// where levels above flatLevel_ have coefficients at the point's
    /// stencil (a node with omega > 0; phi is 0 at the others), and those
    /// levels: bit j for level flatLevel_ + 1 + j. Each (point, level) is
    /// an "entry", point after point
    std::vector<std::pair<std::uint32_t, std::uint32_t>> finerLevelPoints_;
    /// Per entry: how many lone points its stencil meets (the low 15 bits:
    /// its run of finerLonePairs_) and whether a tile of its stencil holds
    /// coefficients (storedEntry: then its stencil's tiles are the next of
    /// finerLevelTiles_; where only lone points' nodes are met, none is)
    std::vector<std::uint16_t> finerEntries_;
    static constexpr std::uint16_t storedEntry = 0x8000;
    /// The stencils' tiles of the entries with storedEntry (-1 for those
    /// that hold no coefficients: levelPlan::storedTiles)
    std::vector<stencilTiles<D>> finerLevelTiles_;
    /// A lone point (levelPlan::lone) j of a level whose nodes a stencil
    /// meets: it adds K times its loneResiduals there (forEachLoneOverlap)
    struct lonePair
    {
        double K;
        std::uint32_t j;
    };
    std::vector<lonePair> finerLonePairs_;          ///< the entries' lone points, entry after entry
    std::pair<int, int> finerLevelsFoundFor_{-1, -1}; ///< (levels planned, flatLevel_) the two were found for
    /// evaluate()'s values in the sweep's (spatial) order, before they are
    /// put in the points' own order (a scratch array kept from call to call:
    /// no new pages per call; hence not safe for concurrent evaluations)
    mutable hugeVector<double> sweptValues_;

    indexBox<D> evalNodeBox(int k) const;
    int chooseFlatLevel(int nLevels, const trendLattice<D>& trend) const;
    void foldLevels(const std::deque<levelPlan<D>>& levels, int nLevels, int m, const affineFit<D>& affine,
                    const trendLattice<D>& trend);
    void addTrend(const indexBox<D>& b, const trendLattice<D>& trend);
    void addAffine(const indexBox<D>& b, const affineFit<D>& affine);
    void addLevelInBox(const levelPlan<D>& L, const indexBox<D>& b);
    bool coefficientWeights(const levelPlan<D>& L, const stencil<D>& st, stencilTiles<D>& tid, double w[3]) const;
    std::vector<std::vector<std::uint8_t>> findFinerLevels(const std::deque<levelPlan<D>>& levels);
    void markReadEveryFit(std::deque<levelPlan<D>>& levels, std::vector<std::vector<std::uint8_t>>& read,
                          int nRanks) const;
    void addFinerLevels(const std::deque<levelPlan<D>>& levels, int nLevels, double* values) const;

public:
    /// The points and domain are kept by reference: they must outlive the object
    flatEvaluator(const evaluationPoints<D>& eval, const controlPoints<D>& ctrl, const domain<D>& dom)
    :
        eval_(eval), ctrl_(ctrl), dom_(dom), nc_(ctrl.nComponents)
    {}

    /// Rebuilds the flat lattice after a fit of the first nLevels of levels
    /// (over the trend and the affine start), and, when the planned levels
    /// changed, which finer levels each point needs; then also which points
    /// of separated levels must be stored in every fit
    /// (levelPlan::readEveryFit). nRanks: the communicator's size
    void update(std::deque<levelPlan<D>>& levels, int nLevels, const affineFit<D>& affine,
                const trendLattice<D>& trend, int nRanks);

    /// Whether a node of L with coefficients lies in the stencil of one of
    /// this rank's evaluation points, in a component the points' mask reads
    bool reads(const levelPlan<D>& L) const;

    /// Whether there is a flat lattice (else evaluate() does not apply)
    bool active() const { return flatLevel_ >= 0; }

    /// The approximation at the evaluation points (point x component, the
    /// points' own order): the flat lattice, then the finer levels of the
    /// first nLevels of levels
    void evaluate(const std::deque<levelPlan<D>>& levels, int nLevels, std::vector<double>& out) const;

    /// Bytes of the flat lattice, the scratch arrays and the finer levels' tables
    std::int64_t bytes() const;
};

} // namespace mba
#endif
