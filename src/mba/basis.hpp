#ifndef MBA_BASIS_HPP
#define MBA_BASIS_HPP
namespace mba {
/// Uniform cubic B-spline basis B0..B3 at s in [0,1) (Lee, Wolberg & Shin 1997, Eq. 2)
void cubicBasis(double s, double w[4]);
}
#endif
