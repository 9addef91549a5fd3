// RBF baseline interpolation: reproduction, affine exactness, decomposition
// independence, greedy selection, bad input
#include "rbfInterpolant.hpp"
#include "testData.hpp"

#include <catch2/catch.hpp>

using namespace bsmTest;
using Catch::Matchers::Contains;

namespace {


template <int D>
void reproducesControlValues(rbf::kernel k)
{
    const auto c = randomPoints<D>(300, 201);
    const auto v = smoothValues<D>(c, 3);
    rbf::params p;
    p.function = k;
    rbf::interpolant<D> s(mba::serial(), p, 3, c);
    s.fit(v);
    std::vector<double> out;
    s.evaluate(c, out);
    INFO(rbf::kernelName(k) << " D " << D << " rcond " << s.stats().rcond);
    for (std::size_t i = 0; i < v.size(); ++i) REQUIRE_THAT(out[i], Catch::WithinAbs(v[i], 1e-10*maxAbs(v)));
}

} // namespace

TEST_CASE("RBF reproduces the control values", "[rbf]")
{
    for (auto k : {rbf::kernel::inverseMultiquadric, rbf::kernel::thinPlateSpline, rbf::kernel::wendlandC2})
    {
        reproducesControlValues<2>(k);
        reproducesControlValues<3>(k);
    }
}

namespace {

/// Every kernel with the polynomial reproduces the affine field g (point,
/// component) of the control points c at the points e
template <class G>
void affineReproduced(const std::vector<mba::point<3>>& c, const std::vector<mba::point<3>>& e, const G& g)
{
    std::vector<double> v;
    for (const auto& x : c) for (int k = 0; k < 3; ++k) v.push_back(g(x, k));
    for (auto kern : {rbf::kernel::inverseMultiquadric, rbf::kernel::thinPlateSpline, rbf::kernel::wendlandC2})
    {
        rbf::params p;
        p.function = kern;
        rbf::interpolant<3> s(mba::serial(), p, 3, c);
        s.fit(v);
        std::vector<double> out;
        s.evaluate(e, out);
        INFO(rbf::kernelName(kern) << " rcond " << s.stats().rcond);
        for (std::size_t i = 0; i < e.size(); ++i)
            for (int k = 0; k < 3; ++k) REQUIRE_THAT(out[3*i + k], Catch::WithinAbs(g(e[i], k), 1e-9));
    }
}

} // namespace

TEST_CASE("RBF with the polynomial reproduces affine motion everywhere", "[rbf]")
{
    affineReproduced(randomPoints<3>(200, 211, -1, 2), randomPoints<3>(400, 212, -1, 2),
        [](const mba::point<3>& x, int k) { return 0.1*k + (k + 1)*0.3*x[0] - 0.2*x[1] + 0.05*k*x[2]; });
}

TEST_CASE("RBF: control points on an axis plane drop that coordinate from the polynomial", "[rbf]")
{
    // (a box face: the polynomial's term across it is undetermined; an
    // affine field in the plane is reproduced everywhere, a translation
    // translates the whole domain)
    auto c = randomPoints<3>(150, 215);
    for (auto& x : c) x[2] = 0.25;
    affineReproduced(c, randomPoints<3>(300, 216),
        [](const mba::point<3>& x, int k) { return 0.1*k + 0.2*(k + 1)*x[0] - 0.3*x[1]; });
}

TEST_CASE("RBF: serial equals 2 and 3 ranks", "[rbf][parallel]")
{
    const auto c = randomPoints<3>(500, 221);
    const auto e = randomPoints<3>(300, 222);
    const auto v = smoothValues<3>(c, 2);
    rbf::params p;
    std::vector<double> ref;
    {
        rbf::interpolant<3> s(mba::serial(), p, 2, c);
        s.fit(v);
        s.evaluate(e, ref);
    }
    for (int P : {2, 3})
    {
        std::vector<double> got(ref.size());
        mba::runSimulated(P, [&](const mba::communicator& comm) {
            std::vector<mba::point<3>> cl;
            std::vector<double> vl;
            for (std::size_t i = 0; i < c.size(); ++i)
                if (int((i*7) % P) == comm.rank()) { cl.push_back(c[i]); vl.push_back(v[2*i]); vl.push_back(v[2*i + 1]); }
            rbf::interpolant<3> s(comm, p, 2, cl);
            s.fit(vl);
            std::vector<mba::point<3>> el;
            std::vector<std::size_t> idx;
            for (std::size_t i = 0; i < e.size(); ++i) if (int(i % P) == comm.rank()) { el.push_back(e[i]); idx.push_back(i); }
            std::vector<double> o;
            s.evaluate(el, o);
            for (std::size_t j = 0; j < idx.size(); ++j) { got[2*idx[j]] = o[2*j]; got[2*idx[j] + 1] = o[2*j + 1]; }
        });
        INFO("ranks " << P);
        for (std::size_t i = 0; i < ref.size(); ++i) REQUIRE_THAT(got[i], Catch::WithinAbs(ref[i], 1e-12));
    }
}

TEST_CASE("RBF greedy selection meets its tolerance with fewer centres", "[rbf]")
{
    const auto c = surfacePoints<3>(20);
    std::vector<double> v;
    for (const auto& x : c) v.push_back(0.1*std::sin(3*x[0])*std::cos(2*x[1]) + 0.05*x[2]);
    rbf::params p;
    p.greedyTolerance = 1e-3;
    p.greedyBatch = 40;
    rbf::interpolant<3> s(mba::serial(), p, 1, c);
    s.fit(v);
    CHECK(s.stats().centres < s.stats().controlPoints);
    CHECK(s.stats().maxError <= 1e-3);
    std::vector<double> out;
    s.evaluate(c, out);
    const double vmax = maxAbs(v);
    for (std::size_t i = 0; i < v.size(); ++i) REQUIRE(std::abs(out[i] - v[i]) <= 1e-3*vmax*(1 + 1e-9));
}

TEST_CASE("RBF greedy selection from one centre a step spans the polynomial first", "[rbf]")
{
    // (its first batch alone, one point, or several on one face of the
    // cube, would leave the linear polynomial undetermined: singular)
    const auto c = surfacePoints<3>(8);
    std::vector<double> v;
    for (const auto& x : c) v.push_back(0.1*std::sin(3*x[0])*std::cos(2*x[1]) + 0.05*x[2]);
    for (int batch : {1, 2, 4})
    {
        rbf::params p;
        p.greedyTolerance = 1e-2;
        p.greedyBatch = batch;
        rbf::interpolant<3> s(mba::serial(), p, 1, c);
        s.fit(v);
        INFO("greedyBatch " << batch << ": " << s.stats().centres << " centres");
        CHECK(s.stats().centres < s.stats().controlPoints);
        CHECK(s.stats().maxError <= 1e-2);
    }
}

TEST_CASE("RBF rejects bad parameters and systems with a clear message", "[rbf][errors]")
{
    const auto c = randomPoints<3>(100, 231);
    rbf::params p;
    SECTION("unknown function") { REQUIRE_THROWS_WITH(rbf::kernelFromName("gaussian"), Contains("inverseMultiquadric thinPlateSpline wendlandC2")); }
    SECTION("shape parameter") { p.shapeParameter = 0; REQUIRE_THROWS_WITH((rbf::interpolant<3>(mba::serial(), p, 1, c)), Contains("shapeParameter")); }
    SECTION("thin-plate spline without polynomial")
    {
        p.function = rbf::kernel::thinPlateSpline;
        p.polynomial = false;
        REQUIRE_THROWS_WITH((rbf::interpolant<3>(mba::serial(), p, 1, c)), Contains("polynomial"));
    }
    SECTION("too large")
    {
        p.maxPoints = 50;
        REQUIRE_THROWS_WITH((rbf::interpolant<3>(mba::serial(), p, 1, c)), Contains("100 control points exceed maxPoints 50") && Contains("MB"));
    }
    SECTION("greedy selection beyond maxPoints")
    {
        p.maxPoints = 20;
        p.greedyTolerance = 1e-6;
        p.greedyBatch = 8;
        std::vector<double> v;
        for (const auto& x : c) v.push_back(std::sin(5*x[0])*std::cos(4*x[1]) + x[2]*x[2]);
        rbf::interpolant<3> s(mba::serial(), p, 1, c);
        REQUIRE_THROWS_WITH(s.fit(v), Contains("the greedy selection needs more than maxPoints 20 centres")
            && Contains("greedyTolerance 1e-06") && !Contains("use greedy selection"));
    }
    SECTION("ill-conditioned")
    {
        // a nearly flat basis: the classic ill-conditioned RBF system
        p.shapeParameter = 1e3;
        REQUIRE_THROWS_WITH((rbf::interpolant<3>(mba::serial(), p, 1, c)), Contains("ill-conditioned") && Contains("shapeParameter"));
    }
    SECTION("non-finite value")
    {
        rbf::interpolant<3> s(mba::serial(), p, 1, c);
        std::vector<double> v(100, 0.0);
        v[4] = std::nan("");
        REQUIRE_THROWS_WITH(s.fit(v), Contains("control value 4"));
    }
}
