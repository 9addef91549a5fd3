#include "basis.hpp"
namespace mba {
void cubicBasis(double s, double w[4])
{
    const double t = 1.0 - s;
    w[0] = t*t*t/6.0;
    w[1] = (3.0*s*s*s - 6.0*s*s + 4.0)/6.0;
    w[2] = (-3.0*s*s*s + 3.0*s*s + 3.0*s + 1.0)/6.0;
    w[3] = s*s*s/6.0;
}
}
