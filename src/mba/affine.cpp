#include "affine.hpp"

#include <algorithm>
#include <cmath>

namespace mba {

std::vector<double> pseudoInverse(const std::vector<double>& A0, int n, double relTol)
{
    // Cyclic Jacobi eigen-decomposition A = V diag(l) V^T
    std::vector<double> A(A0), V(n*n, 0.0);
    for (int i = 0; i < n; ++i) V[i*n + i] = 1;
    for (int sweep = 0; sweep < 100; ++sweep)
    {
        double off = 0, diag = 0;
        for (int i = 0; i < n; ++i)
        {
            diag += A[i*n + i]*A[i*n + i];
            for (int j = i + 1; j < n; ++j) off += A[i*n + j]*A[i*n + j];
        }
        if (off <= 1e-30*diag || off == 0) break;
        for (int p = 0; p < n; ++p)
            for (int q = p + 1; q < n; ++q)
            {
                const double apq = A[p*n + q];
                if (apq == 0) continue;
                const double theta = (A[q*n + q] - A[p*n + p])/(2*apq);
                const double t = (theta >= 0 ? 1 : -1)/(std::abs(theta) + std::sqrt(theta*theta + 1));
                const double c = 1/std::sqrt(t*t + 1), s = t*c;
                for (int k = 0; k < n; ++k)
                {
                    const double akp = A[k*n + p], akq = A[k*n + q];
                    A[k*n + p] = c*akp - s*akq;
                    A[k*n + q] = s*akp + c*akq;
                }
                for (int k = 0; k < n; ++k)
                {
                    const double apk = A[p*n + k], aqk = A[q*n + k];
                    A[p*n + k] = c*apk - s*aqk;
                    A[q*n + k] = s*apk + c*aqk;
                }
                for (int k = 0; k < n; ++k)
                {
                    const double vkp = V[k*n + p], vkq = V[k*n + q];
                    V[k*n + p] = c*vkp - s*vkq;
                    V[k*n + q] = s*vkp + c*vkq;
                }
            }
    }
    double lmax = 0;
    for (int i = 0; i < n; ++i) lmax = std::max(lmax, std::abs(A[i*n + i]));
    std::vector<double> P(n*n, 0.0);
    for (int k = 0; k < n; ++k)
    {
        const double l = A[k*n + k];
        if (!(l > relTol*lmax) || l <= 0) continue;
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) P[i*n + j] += V[i*n + k]*V[j*n + k]/l;
    }
    return P;
}

template <int D>
affineFit<D>::affineFit(const communicator& comm, int nc, pointsView<D> x,
                        const std::vector<std::uint8_t>& mask, const point<D>& centre, double scale)
:
    nc_(nc), centre_(centre), invScale_(1/scale)
{
    constexpr int n = D + 1;
    std::vector<double> A(nc*n*n, 0.0);
    double b[n];
    for (std::size_t p = 0; p < x.size; ++p)
    {
        basis(x[p], b);
        for (int c = 0; c < nc; ++c)
        {
            if (!mask.empty() && !mask[p*nc + c]) continue;
            for (int i = 0; i < n; ++i)
                for (int j = 0; j < n; ++j) A[(c*n + i)*n + j] += b[i]*b[j];
        }
    }
    A = comm.sum(A);
    // Each component's minimum-norm fit about the centroid m of its own
    // points (in the basis (1, u - m) = M (1, u), M = [1 0; -m I]): where
    // they leave a direction undetermined (all in a plane), the fit has no
    // gradient along it wherever that plane lies. Its coefficients in the
    // common basis: M^T pinv(M A M^T) M rhs (A^-1 where A is regular)
    pinv_.resize(nc*n*n);
    for (int c = 0; c < nc; ++c)
    {
        const double* Ac = &A[c*n*n];
        std::vector<double> M(n*n, 0.0);
        for (int i = 0; i < n; ++i) M[i*n + i] = 1;
        if (Ac[0] > 0)
        {
            for (int i = 1; i < n; ++i) M[i*n] = -Ac[i]/Ac[0];
        }
        // MA = M A, then A' = MA M^T
        std::vector<double> MA(n*n, 0.0), Ap(n*n, 0.0);
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j)
                for (int k = 0; k < n; ++k) MA[i*n + j] += M[i*n + k]*Ac[k*n + j];
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j)
                for (int k = 0; k < n; ++k) Ap[i*n + j] += MA[i*n + k]*M[j*n + k];
        const std::vector<double> P = pseudoInverse(Ap, n);
        // M^T P M
        std::vector<double> PM(n*n, 0.0);
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j)
                for (int k = 0; k < n; ++k) PM[i*n + j] += P[i*n + k]*M[k*n + j];
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j)
            {
                double t = 0;
                for (int k = 0; k < n; ++k) t += M[k*n + i]*PM[k*n + j];
                pinv_[(c*n + i)*n + j] = t;
            }
    }
    coeff_.assign(nc*n, 0.0);
}

template <int D>
void affineFit<D>::solve(const communicator& comm, pointsView<D> x, const std::vector<std::uint8_t>& mask,
                         const std::vector<double>& values)
{
    constexpr int n = D + 1;
    std::vector<double> rhs(nc_*n, 0.0);
    double b[n];
    for (std::size_t p = 0; p < x.size; ++p)
    {
        basis(x[p], b);
        for (int c = 0; c < nc_; ++c)
        {
            if (!mask.empty() && !mask[p*nc_ + c]) continue;
            for (int i = 0; i < n; ++i) rhs[c*n + i] += b[i]*values[p*nc_ + c];
        }
    }
    rhs = comm.sum(rhs);
    for (int c = 0; c < nc_; ++c)
        for (int i = 0; i < n; ++i)
        {
            double s = 0;
            for (int j = 0; j < n; ++j) s += pinv_[(c*n + i)*n + j]*rhs[c*n + j];
            coeff_[c*n + i] = s;
        }
}

template class affineFit<2>;
template class affineFit<3>;

} // namespace mba
