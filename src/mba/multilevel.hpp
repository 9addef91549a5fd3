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
// holds its own partial sums ("own" tiles) and receives, from the ranks that
// hold partial sums on the tiles its own points' stencils touch, exactly those
// tiles (or the residuals of the few points behind them), adding them in rank
// order, so every rank that sees a node gets bitwise the same phi there.
//
// This header is the interface; the parts live in internal headers:
// pointSets.hpp and spatialOrder.hpp (the points in spatial order),
// levelPlan.hpp (a level's plan: tiles, buckets, requests, ghosts, the
// separation test; levelPlanner.hpp the planner that makes it), levelApply.hpp (a level's apply in every fit),
// flatEvaluator.hpp with subdivision.hpp and plainLattice.hpp (evaluation),
// trendLattice.hpp (a trend under the levels: fit with a trend),
// lattice.hpp and stencilKernels.hpp (tiled lattices and their kernels).
#ifndef MBA_MULTILEVEL_HPP
#define MBA_MULTILEVEL_HPP

#include "communicator.hpp"
#include "geometry.hpp"
#include "vectorWidth.hpp"

#include <cstdint>
#include <memory>
#include <vector>

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
    /// so that any affine motion of all control points (translations, rotations,
    /// scalings, shears) is reproduced exactly everywhere (default on: a rigid motion of
    /// the whole boundary then moves the whole mesh rigidly)
    bool affine = true;
    /// Padding of the bounding box on each side, relative to its largest extent (> 0)
    double padding = 1e-3;
    /// Target number of tiles per exchange bucket (>= 1)
    int bucketTiles = 32;
    /// How a level's partial sums meet (parallel only): direct (every
    /// contributor sends its partial sums, or the residuals of its points
    /// near them, to every rank that reads them), chunked (each shared
    /// tile's nodes are split into chunks, one per contributor, which sums
    /// that chunk and sends it to the tile's readers: what a rank receives is
    /// bounded by the tiles it reads, however many ranks contribute), tree
    /// (the level's tiles of all ranks summed through a binary tree of the
    /// ranks, treeSum.hpp: 2 log2(P) messages a rank, about twice the
    /// level's tiles received; it gathers the level's tile keys once) or
    /// automatic (per level, chunked where it makes the busiest rank receive
    /// fewer bytes than direct, and tree where it makes the level's exchange
    /// cheaper than that choice in a latency-bandwidth model with
    /// InfiniBand-class parameters, which happens on coarse levels that
    /// many ranks share). Direct and chunked sum in rank order and give the
    /// same values bit for bit; tree sums in its tree's order (equal to
    /// round-off). Every choice gives every rank that holds a node the same
    /// value. Levels whose control points are separated always exchange
    /// directly.
    enum class exchangeMode { automatic, direct, chunked, tree };
    exchangeMode exchange = exchangeMode::automatic;
    /// Stop before a level that no evaluation point reads: where none of
    /// the level's nodes with coefficients lies in an evaluation point's
    /// stencil (in a component the evaluation mask asks for), neither do
    /// any finer level's, so those levels would only bring the control
    /// points' residuals down, and evaluate() gives the same values without
    /// them. Off by default: evaluate(x) and evaluateControl() then see
    /// every level the tolerance needs.
    bool stopUnread = false;

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
    std::int64_t lonePoints = 0;          ///< this rank's points alone at their nodes (levelPlan::lone)
    std::int64_t nodes = 0;               ///< node slots stored in the view
    std::int64_t bytes = 0;               ///< bytes of the level (view data, layouts)
    std::int64_t buckets = 0;             ///< this rank's buckets
    std::int64_t tilesSent = 0, tilesReceived = 0; ///< per apply, to / from other ranks
    std::int64_t ghostsSent = 0, ghostsReceived = 0; ///< control points whose residuals are sent instead of tiles
    std::int64_t messagesSent = 0, messagesReceived = 0;
    bool chunked = false;                 ///< the level's partial sums meet in chunks (params::exchange)
    bool tree = false;                    ///< the level's partial sums meet in a tree of the ranks (params::exchange)
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
    /// Stopped above the threshold before a level that no evaluation point
    /// reads (params::stopUnread), maxLevels' next included
    bool unread = false;
};

template <int D>
class multilevel
{
    struct state;                   ///< the plan, the levels and the work arrays (multilevel.cpp)
    std::unique_ptr<state> state_;
    state& self() { return *state_; }
    const state& self() const { return *state_; }   ///< (const members see the state const)

public:
    /// The plan. control, evaluation: this rank's points (not copied: they must
    /// outlive the object). mask: per control point x component 0/1 (empty: all
    /// constrained). The domain is the padded bounding box of all ranks' control
    /// and evaluation points, unless bounds is given (it must contain them).
    /// Collective.
    multilevel(const communicator& comm, const params& p, int nComponents,
               pointsView<D> control, std::vector<std::uint8_t> mask,
               pointsView<D> evaluation, const box<D>* bounds = nullptr);
    /// The same, and which values the caller reads at the evaluation points:
    /// evaluationMask per evaluation point x component 0/1 (empty: all), for
    /// params::stopUnread (evaluate() still gives every component)
    multilevel(const communicator& comm, const params& p, int nComponents,
               pointsView<D> control, std::vector<std::uint8_t> mask,
               pointsView<D> evaluation, std::vector<std::uint8_t> evaluationMask,
               const box<D>* bounds = nullptr);
    /// The plan keeps the communicator: a temporary one would dangle
    multilevel(const communicator&&, const params&, int, pointsView<D>, std::vector<std::uint8_t>,
               pointsView<D>, const box<D>* = nullptr) = delete;
    multilevel(const communicator&&, const params&, int, pointsView<D>, std::vector<std::uint8_t>,
               pointsView<D>, std::vector<std::uint8_t>, const box<D>* = nullptr) = delete;
    ~multilevel();

    /// Fit the control values (point x component; unconstrained components are
    /// ignored). Collective. Repeated fits reuse the plan.
    const fitReport& fit(const std::vector<double>& values);

    /// The same over a trend: the cubic B-spline of level k whose coefficients
    /// are trend (node x component, at the nodes latticeNodes(k) lists, the
    /// same on every rank) is subtracted at the control points before the
    /// affine start and the levels, and added back in every evaluation (at no
    /// cost per evaluation point: it joins the coarse levels). A smooth trend
    /// sampled there (a thin-plate spline through a subset of the control
    /// points, say) then shapes the field away from the control points, where
    /// the levels fall back towards the smooth interpolation of all the data.
    /// Collective.
    const fitReport& fit(const std::vector<double>& values, int k, const std::vector<double>& trend);

    /// The nodes of level k's lattice over the whole domain (node x coordinate,
    /// the last direction fastest): where fit() takes a trend's coefficients
    std::vector<double> latticeNodes(int k) const;

    // The evaluations are const but fill caches (the coefficients a fit
    // leaves for later, a scratch array): one thread at a time per object.

    /// The approximation at the planned evaluation points (point x component)
    void evaluate(std::vector<double>& out) const;

    /// The approximation at x (serial communicator only: in parallel a rank holds
    /// the lattices only near its own planned points); throws std::out_of_range
    /// outside the domain
    void evaluate(const double* x, double* out) const;

    /// The approximation at this rank's control points (point x component)
    void evaluateControl(std::vector<double>& out) const;

    const domain<D>& dom() const;
    const fitReport& report() const;
    std::vector<levelStats> stats() const;
    /// Bytes held by the plan (levels and work arrays)
    std::int64_t bytes() const;
    /// Bytes each rank would receive if it gathered every control point instead
    std::int64_t gatherAllBytes() const;
    int nComponents() const;
};

} // namespace mba
#endif
