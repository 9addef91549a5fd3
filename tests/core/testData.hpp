// Seeded test data for the core tests
#ifndef BSM_TEST_DATA_HPP
#define BSM_TEST_DATA_HPP

#include "multilevel.hpp"

#include <cmath>
#include <random>
#include <vector>

namespace bsmTest {

template <int D>
std::vector<mba::point<D>> randomPoints(std::size_t n, unsigned seed, double lo = 0, double hi = 1)
{
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> U(lo, hi);
    std::vector<mba::point<D>> p(n);
    for (auto& x : p) for (auto& c : x) c = U(rng);
    return p;
}

/// k points per edge of every face of the unit cube (D=3) / square (D=2)
template <int D>
std::vector<mba::point<D>> surfacePoints(int k)
{
    std::vector<mba::point<D>> p;
    for (int d = 0; d < D; ++d)
        for (int side = 0; side < 2; ++side)
            for (long i = 0; i < (D == 3 ? long(k)*k : k); ++i)
            {
                mba::point<D> x;
                x[d] = side;
                x[(d + 1) % D] = double(i % k)/(k - 1);
                if (D == 3) x[(d + 2) % D] = double(i / k)/(k - 1);
                p.push_back(x);
            }
    return p;
}

/// Smooth vector field, component c
template <int D>
double smooth(const mba::point<D>& x, int c)
{
    double s = std::sin(2.1*x[0] + c)*std::cos(1.3*x[1] - 0.5*c);
    if (D == 3) s += 0.5*std::sin(1.7*x[2] + 0.3*c);
    return s;
}

template <int D>
std::vector<double> smoothValues(const std::vector<mba::point<D>>& p, int nc)
{
    std::vector<double> v(p.size()*nc);
    for (std::size_t i = 0; i < p.size(); ++i)
        for (int c = 0; c < nc; ++c) v[i*nc + c] = smooth<D>(p[i], c);
    return v;
}

inline double maxAbs(const std::vector<double>& v)
{
    double m = 0;
    for (double x : v) m = std::max(m, std::abs(x));
    return m;
}

} // namespace bsmTest
#endif
