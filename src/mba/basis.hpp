#ifndef MBA_BASIS_HPP
#define MBA_BASIS_HPP
namespace mba {
/// Uniform cubic B-spline basis B0..B3 at s in [0,1) (Lee, Wolberg & Shin 1997, Eq. 2):
/// non-negative, summing to one. T: double, or a vector of doubles (GCC's
/// vector extension) for the basis of several points at once, lane by lane
/// the same arithmetic
template <class T>
inline void cubicBasis(T s, T w[4])
{
    // times 1/6 rather than divided by 6: the evaluation's hottest few flops
    constexpr double sixth = 1.0/6.0;
    const T t = 1.0 - s, s2 = s*s, s3 = s2*s;
    w[0] = t*t*t*sixth;
    w[1] = (3.0*s3 - 6.0*s2 + 4.0)*sixth;
    w[2] = (-3.0*s3 + 3.0*s2 + 3.0*s + 1.0)*sixth;
    w[3] = s3*sixth;
}
}
#endif
