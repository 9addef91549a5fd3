// bsplineMorph: OpenFOAM-free multilevel B-spline core
// Multilevel B-spline approximation of scattered vector data (Lee, Wolberg &
// Shin 1997), distributed over the ranks of a communicator (the paper's
// Section 4; a serialCommunicator gives the plain serial method).
//
// Plan once, apply many: the constructor takes the geometry (control points,
// per-component masks, evaluation points) and fixes the domain and everything
// that depends only on it; the lattices of the levels (tile layouts, omega,
// buckets and the communication pattern) are built the first time a fit needs
// them and kept. fit(values) then only moves values: scatter delta, exchange
// partial delta of shared tiles, phi = delta/omega, update the residuals.
//
// One level (the paper's Eq. 5-6): a control point c with residual r_c and
// stencil weights w (4^D nodes) proposes phi_c = w r_c / sum(w^2) to its nodes;
// each node keeps delta = sum w^2 phi_c and omega = sum w^2 and phi = delta/omega.
// delta and omega are sums, so partial sums from different ranks add. Each rank
// holds its own partial sums ("own" tiles), clusters them into buckets whose
// index boxes are all-gathered (a small directory of who holds what). Each rank
// then asks the owners of the buckets that meet the stencils of its own query
// points (its control and evaluation points) for exactly the tiles those
// stencils touch, receives their partial sums point to point and adds them in
// rank order, so every rank that sees a node gets bitwise the same phi there.
// At fine levels the owner's control points that touch the asked tiles are
// fewer than the tiles' nodes: the owner then sends their coordinates once and
// their residuals per fit ("ghosts"), and the asking rank computes the owner's
// partial sums itself, with the same points in the same order (bitwise equal).
#ifndef MBA_MULTILEVEL_HPP
#define MBA_MULTILEVEL_HPP

#include "affine.hpp"
#include "communicator.hpp"
#include "hugePages.hpp"
#include "lattice.hpp"

#include <memory>

namespace mba {

/// Parameters of the approximation
struct params
{
    /// Stop when the largest control-point residual is at or below this
    double tolerance = 1e-6;
    /// tolerance is relative to the largest |control value| (else absolute)
    bool relative = true;
    /// Upper bound on the number of B-spline levels (>= 1)
    int maxLevels = 12;
    /// Cells along the longest edge of the domain at level 0 (>= 1)
    int initialGrid = 1;
    /// Least-squares affine initial approximation, subtracted before the levels,
    /// so that translations, rotations-free shears and scalings of all control
    /// points are reproduced exactly everywhere (default on: a rigid motion of
    /// the whole boundary then moves the whole mesh rigidly)
    bool affine = true;
    /// Padding of the bounding box on each side, relative to its largest extent (> 0)
    double padding = 1e-3;
    /// Target number of tiles per exchange bucket (>= 1)
    int bucketTiles = 32;

    /// Throws std::invalid_argument naming the offending parameter
    void validate() const;
};

/// Statistics of one level
struct levelStats
{
    int level = 0;
    double h = 0;                         ///< cell edge
    std::int64_t ownTiles = 0;            ///< tiles holding this rank's partial sums
    std::int64_t viewTiles = 0;           ///< tiles of the rank's view (own + received)
    bool dense = false;                   ///< view stored densely
    bool separated = false;               ///< no two control points share a node (phi stored directly)
    std::int64_t nodes = 0;               ///< node slots stored in the view
    std::int64_t bytes = 0;               ///< bytes of the level (view data, layouts)
    std::int64_t buckets = 0;             ///< this rank's buckets
    std::int64_t tilesSent = 0, tilesReceived = 0; ///< per apply, to / from other ranks
    std::int64_t ghostsSent = 0, ghostsReceived = 0; ///< control points whose residuals are sent instead of tiles
    std::int64_t messagesSent = 0, messagesReceived = 0;
    std::int64_t bytesSentPerApply = 0, bytesReceivedPerApply = 0;
    double maxResidual = 0, rmsResidual = 0; ///< after this level (global)
    double seconds = 0;                   ///< time of the last apply of this level
    double planSeconds = 0;               ///< time to build the level
};

/// Result of one fit
struct fitReport
{
    int levels = 0;                 ///< levels used
    double threshold = 0;           ///< absolute residual threshold applied
    double maxValue = 0;            ///< largest |control value| (global)
    double initialMaxResidual = 0;  ///< after the affine part (before any level)
    double maxResidual = 0;         ///< final (global)
    double rmsResidual = 0;         ///< final (global)
    double seconds = 0;
    bool converged = false;         ///< maxResidual <= threshold
};

template <int D>
class multilevel
{
    struct level;

    const communicator& comm_;
    params p_;
    int nc_, nw_;                       ///< components; omega values per node (1 or nc)
    pointsView<D> ctrl_, eval_;
    std::vector<std::uint8_t> mask_;    ///< per control point x component, empty: all
    std::vector<std::uint8_t> active_;  ///< control point constrains something
    domain<D> dom_;
    affineFit<D> affine_;
    std::vector<box<D>> queryBoxes_;    ///< clusters of this rank's control and evaluation points
    std::vector<std::vector<const double*>> queryGroups_; ///< the points of each cluster
    std::vector<std::uint32_t> ctrlOrder_; ///< active control points in space-filling-curve order
    std::vector<std::uint32_t> evalOrder_; ///< evaluation points in curve order (empty: their own order)
    std::size_t evalAt(std::size_t q) const { return evalOrder_.empty() ? q : evalOrder_[q]; }
    std::vector<point<D>> ctrlU0_;      ///< level-0 local coordinates of the active control points, in ctrlOrder_
    hugeVector<point<D>> evalU0_;       ///< the same of the evaluation points, in evalOrder_
    std::vector<stencil<D>> stencils_;  ///< a fit's control-point stencils at the current level
    std::vector<stencil<D>> cubed_;     ///< the same with their weights cubed (for the scatter)
    std::vector<std::uint32_t> evalPos_; ///< position of each evaluation point in evalOrder_ (curve order only)
    mutable hugeVector<double> sweep_;  ///< evaluate()'s values in curve order (kept: no new pages per call)
    std::vector<std::unique_ptr<level>> levels_;
    std::vector<double> residual_, scratch_;
    std::vector<double> rr_;            ///< a fit's r/sum(w^2) per control point x component at the current level
    std::vector<double> atCtrl_;        ///< the current level's values at the control points (in ctrlOrder_)
    /// Levels 0..flat_ refined (B-spline subdivision: exact) and summed, with
    /// the affine approximation (reproduced exactly by its node values), into
    /// one plain, untiled lattice over the level-flat_ nodes that the planned
    /// evaluation points' stencils touch (flatBox_), so that most points cost
    /// one contiguous stencil; flat_ is the finest level whose box has at most
    /// as many nodes as there are evaluation points (-1: none)
    int flat_ = -1;
    point<D> evalLo0_, evalHi0_;        ///< level-0 local box of the evaluation points
    indexBox<D> flatBox_;
    hugeVector<double> flatPhi_, foldScratch_;
    /// The evaluation points (positions in evalOrder_, ascending) where levels
    /// above flat_ have coefficients at the point's stencil (a node with
    /// omega > 0; phi is 0 at the others), and those levels: bit j for level
    /// flat_ + 1 + j
    std::vector<std::pair<std::uint32_t, std::uint32_t>> deepLevels_;
    /// Their stencils' tiles, point after point in evalOrder_
    std::vector<stencilTiles<D>> deepTiles_;
    std::pair<int, int> deepKey_{-1, -1}; ///< (levels built, flat_) deepLevels_ was found for
    fitReport report_;
    std::int64_t nCtrlGlobal_ = 0;

    void buildLevel(int k);
    void applyLevel(level& L);
    template <class F> void forOwnStencils(const level& L, F&& f) const;
    /// The stencil of control point ctrlOrder_[q] at level L
    stencil<D> ctrlStencil(const level& L, std::size_t q) const;
    void residualStats(double& maxr, double& rms) const;
    void addLevels(const double* x, double* out, int nLevels) const;
    void fold();
    indexBox<D> evalNodeBox(int k) const;
    /// Stores the coefficients that separated levels leave out per fit (level::readEveryFit)
    void completeLattices() const;
    /// The components control point i constrains, in on[0..nc): on, or
    /// nullptr when every active point constrains all (one omega per node)
    const bool* constrained(std::size_t i, bool* on) const
    {
        if (nw_ == 1) return nullptr;
        for (int c = 0; c < nc_; ++c) on[c] = mask_[i*nc_ + c] != 0;
        return on;
    }

public:
    /// The plan. control, evaluation: this rank's points (not copied: they must
    /// outlive the object). mask: per control point x component 0/1 (empty: all
    /// constrained). The domain is the padded bounding box of all ranks' control
    /// and evaluation points, unless bounds is given (it must contain them).
    /// Collective.
    multilevel(const communicator& comm, const params& p, int nComponents,
               pointsView<D> control, std::vector<std::uint8_t> mask,
               pointsView<D> evaluation, const box<D>* bounds = nullptr);
    /// The plan keeps the communicator: a temporary one would dangle
    multilevel(const communicator&&, const params&, int, pointsView<D>, std::vector<std::uint8_t>,
               pointsView<D>, const box<D>* = nullptr) = delete;
    ~multilevel();

    /// Fit the control values (point x component; unconstrained components are
    /// ignored). Collective. Repeated fits reuse the plan.
    const fitReport& fit(const std::vector<double>& values);

    /// The approximation at the planned evaluation points (point x component)
    void evaluate(std::vector<double>& out) const;

    /// The approximation at x (serial communicator only: in parallel a rank holds
    /// the lattices only near its own planned points); throws std::out_of_range
    /// outside the domain
    void evaluate(const double* x, double* out) const;

    /// The approximation at this rank's control points (point x component)
    void evaluateControl(std::vector<double>& out) const;

    const domain<D>& dom() const { return dom_; }
    const fitReport& report() const { return report_; }
    std::vector<levelStats> stats() const;
    /// Bytes held by the plan (levels and work arrays)
    std::int64_t bytes() const;
    /// Bytes each rank would receive if it gathered every control point instead
    std::int64_t gatherAllBytes() const;
    int nComponents() const { return nc_; }
};

} // namespace mba
#endif
