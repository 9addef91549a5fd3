#include <catch2/catch.hpp>
#include "basis.hpp"

TEST_CASE("cubic B-spline weights are a partition of unity", "[core][basis]")
{
    for (int i = 0; i <= 100; ++i)
    {
        double w[4];
        mba::cubicBasis(i/100.0, w);
        double sum = 0;
        for (double x : w) { REQUIRE(x >= 0.0); sum += x; }
        REQUIRE_THAT(sum, Catch::WithinAbs(1.0, 1e-15));
    }
}
