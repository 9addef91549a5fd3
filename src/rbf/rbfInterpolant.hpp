// bsplineMorph: OpenFOAM-free radial basis function interpolation, the baseline
// the multilevel B-splines are compared with (the "industry" RBF morpher).
//
// s(x) = sum_j a_j phi(|x - x_j|) + p(x), p linear (optional), with
//   sum_j a_j phi(|x_i - x_j|) + p(x_i) = v_i and sum_j a_j [1, x_j] = 0.
// Kernels: inverse multiquadric 1/sqrt(r^2 + c^2), thin-plate spline r^2 log r
// (needs the polynomial), Wendland C2 (1 - r/R)^4 (4 r/R + 1) with support R.
//
// Parallel the way RBF morphers usually are: every rank gathers every control
// point (through mba::communicator) and solves the same system. The gathered
// points are put in a canonical order (sorted by coordinates; points that
// coincide to 1e-10 of the bounding-box diagonal are one centre), so the system,
// its solution and every evaluation are bitwise independent of the
// decomposition. The dense symmetric system is factored once (LAPACK dsytrf)
// per set of control points; each set of values is then one solve (dsytrs).
#ifndef RBF_INTERPOLANT_HPP
#define RBF_INTERPOLANT_HPP

#include "communicator.hpp"
#include "geometry.hpp"

#include <string>
#include <vector>

namespace rbf {

using mba::point;
using mba::pointsView;

enum class kernel { inverseMultiquadric, thinPlateSpline, wendlandC2 };

/// Kernel from its name; throws std::invalid_argument listing the valid names
kernel kernelFromName(const std::string& name);
std::string kernelName(kernel k);

struct params
{
    /// Basis function
    kernel function = kernel::inverseMultiquadric;
    /// Inverse multiquadric c, relative to the control points' bounding-box diagonal (> 0)
    double shapeParameter = 0.05;
    /// Wendland C2 support radius, relative to the bounding-box diagonal (> 0)
    double supportRadius = 0.5;
    /// Linear polynomial augmentation: affine motions reproduced exactly
    bool polynomial = true;
    /// Largest system (control points) allowed; larger is an error naming the memory it would need
    long maxPoints = 20000;
    /// Greedy control-point selection: 0 = off (all points), else the largest
    /// interpolation error allowed at the control points, relative to the largest value
    double greedyTolerance = 0;
    /// Points added per greedy step (>= 1)
    int greedyBatch = 50;
    /// Smallest reciprocal condition number accepted (LAPACK dsycon estimate)
    double minRcond = 1e-15;

    void validate() const;
};

/// Statistics of the current system
struct systemStats
{
    long controlPoints = 0;   ///< gathered, all ranks
    long centres = 0;         ///< used as RBF centres (fewer with greedy selection)
    long size = 0;            ///< system size (centres + polynomial terms)
    double rcond = 0;         ///< reciprocal condition estimate
    double bytes = 0;         ///< factor and centres
    double setupSeconds = 0;  ///< gather, assemble, factor (and greedy selection)
    double maxError = 0;      ///< greedy: largest error at the control points (relative)
    std::int64_t gatheredBytes = 0; ///< bytes this rank received in the gather
};

template <int D>
class interpolant
{
    const mba::communicator& comm_;
    params p_;
    int nc_;
    std::vector<point<D>> x_;        ///< all control points, canonical order
    std::vector<std::size_t> localToGlobal_; ///< this rank's control points in x_
    std::vector<std::size_t> centres_;       ///< indices into x_ used as centres
    point<D> lo_{};
    double scale_ = 1, c2_ = 1, R_ = 1;
    std::vector<double> lu_;         ///< dsytrf factor (n x n, column major)
    std::vector<int> ipiv_;
    std::vector<double> coeff_;      ///< per component: centres' a, then polynomial
    systemStats stats_;

    double phi(double r2) const;
    /// The factor of the squared distances that phi takes in an evaluation
    /// (thinPlateSpline: in units of scale_)
    double r2Scale() const { return p_.function == kernel::thinPlateSpline ? 1/(scale_*scale_) : 1.0; }
    /// phi at x for centre j (of centres_), the squared distance times r2scale
    double kernelAt(const double* x, long j, double r2scale) const
    {
        const point<D>& xj = x_[centres_[j]];
        double r2 = 0;
        for (int d = 0; d < D; ++d) r2 += (x[d] - xj[d])*(x[d] - xj[d]);
        return phi(r2*r2scale);
    }
    void factor(const std::vector<std::size_t>& centres);
    void solve(const std::vector<double>& globalValues);
    void evaluateAt(const double* x, double* out) const;

public:
    /// Collective: gathers the control points of all ranks and factors the
    /// system (with greedy selection: for the values given first, see fit)
    interpolant(const mba::communicator& comm, const params& p, int nComponents, pointsView<D> control);
    /// The interpolant keeps the communicator: a temporary one would dangle
    interpolant(const mba::communicator&&, const params&, int, pointsView<D>) = delete;

    /// Collective: coefficients for this rank's control values (point x component).
    /// With greedy selection the centres are chosen at the first fit and kept.
    void fit(const std::vector<double>& values);

    /// The interpolant at points (point x component)
    void evaluate(pointsView<D> x, std::vector<double>& out) const;

    /// Its basis at the points x (point x (the centres' kernels, then the
    /// polynomial's terms)), kept by the caller for evaluations at the same
    /// points after each fit: a product per value, no kernel per centre
    std::vector<double> basisAt(pointsView<D> x) const;

    /// The interpolant at the points whose basisAt() basis is (point x component)
    void evaluate(const std::vector<double>& basis, std::vector<double>& out) const;

    const systemStats& stats() const { return stats_; }
};

} // namespace rbf
#endif
