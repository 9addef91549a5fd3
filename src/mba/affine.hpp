// bsplineMorph: OpenFOAM-free multilevel B-spline core
// Least-squares affine approximation g(x) = a + B x of vector data (per component
// with its own point set), the geometric part (normal matrices and their
// pseudo-inverses) built once, the coefficients solved per set of values.
// Each component's minimum-norm fit is taken about the centroid of its own
// points: a direction they leave undetermined gets no gradient.
#ifndef MBA_AFFINE_HPP
#define MBA_AFFINE_HPP

#include "communicator.hpp"
#include "geometry.hpp"

#include <vector>

namespace mba {

/// Pseudo-inverse of a symmetric positive semi-definite n x n matrix (row
/// major), eigenvalues below relTol*largest treated as zero (minimum-norm
/// least squares for rank-deficient point sets: collinear, coplanar, few points)
std::vector<double> pseudoInverse(const std::vector<double>& A, int n, double relTol = 1e-10);

template <int D>
class affineFit
{
    int nc_ = 0;
    point<D> centre_{};
    double invScale_ = 1;        ///< 1/scale: a multiplication per coordinate (evaluated at every mesh point)
    std::vector<double> pinv_;   ///< per component (D+1)^2
    std::vector<double> coeff_;  ///< per component D+1 (in scaled coordinates)

    void basis(const double* x, double* b) const
    {
        b[0] = 1;
        for (int d = 0; d < D; ++d) b[d + 1] = (x[d] - centre_[d])*invScale_;
    }

public:
    affineFit() = default;

    /// Geometry: points, per point x component mask (empty: all), reduced over ranks
    affineFit(const communicator& comm, int nc, pointsView<D> x, const std::vector<std::uint8_t>& mask,
              const point<D>& centre, double scale);

    /// Coefficients for values (point x component), reduced over ranks
    void solve(const communicator& comm, pointsView<D> x, const std::vector<std::uint8_t>& mask,
               const std::vector<double>& values);

    void zero() { coeff_.assign(coeff_.size(), 0.0); }

    /// Adds g(x) to out[0..nc)
    void addTo(const double* x, double* out) const
    {
        if (coeff_.empty()) return;
        double b[D + 1];
        basis(x, b);
        for (int c = 0; c < nc_; ++c)
        {
            double s = 0;
            for (int i = 0; i <= D; ++i) s += coeff_[c*(D + 1) + i]*b[i];
            out[c] += s;
        }
    }
};

} // namespace mba
#endif
