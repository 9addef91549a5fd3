// bsplineMorph core tests: bad input gets a clear error; degenerate input
// (no control points, all on a plane or a line, duplicates) has documented
// results
#include "flatEvaluator.hpp"
#include "testData.hpp"

#include <catch2/catch.hpp>

#include <limits>

using namespace mba;
using namespace bsmTest;
using Catch::Matchers::Contains;

TEST_CASE("bad input gets a clear error", "[core][errors]")
{
    auto c = randomPoints<3>(20, 51);
    auto e = randomPoints<3>(20, 52);
    const params p;
    SECTION("non-finite control coordinate")
    {
        c[3][1] = std::numeric_limits<double>::quiet_NaN();
        REQUIRE_THROWS_WITH((multilevel<3>(serial(), p, 1, c, {}, e)), Contains("control point 3") && Contains("non-finite"));
    }
    SECTION("non-finite evaluation coordinate")
    {
        e[7][0] = std::numeric_limits<double>::infinity();
        REQUIRE_THROWS_WITH((multilevel<3>(serial(), p, 1, c, {}, e)), Contains("evaluation point 7"));
    }
    SECTION("non-finite value")
    {
        multilevel<3> m(serial(), p, 1, c, {}, e);
        std::vector<double> v(20, 1.0);
        v[5] = std::numeric_limits<double>::quiet_NaN();
        REQUIRE_THROWS_WITH(m.fit(v), Contains("control value 5") && Contains("not finite"));
    }
    SECTION("mismatched sizes")
    {
        multilevel<3> m(serial(), p, 2, c, {}, e);
        REQUIRE_THROWS_WITH(m.fit(std::vector<double>(20, 1.0)), Contains("20 control values, expected 40"));
        REQUIRE_THROWS_WITH((multilevel<3>(serial(), p, 2, c, std::vector<std::uint8_t>(3, 1), e)), Contains("mask"));
        REQUIRE_THROWS_WITH((multilevel<3>(serial(), p, 2, c, {}, e, std::vector<std::uint8_t>(3, 1))),
            Contains("the evaluation mask has 3 entries, expected 40 (evaluation points x components)"));
    }
    SECTION("zero or negative parameters")
    {
        params q;
        q.maxLevels = 0;
        REQUIRE_THROWS_WITH((multilevel<3>(serial(), q, 1, c, {}, e)), Contains("maxLevels"));
        q = params();
        q.tolerance = -1;
        REQUIRE_THROWS_WITH((multilevel<3>(serial(), q, 1, c, {}, e)), Contains("tolerance"));
        q = params();
        q.initialGrid = 0;
        REQUIRE_THROWS_WITH((multilevel<3>(serial(), q, 1, c, {}, e)), Contains("initialGrid"));
        q = params();
        q.padding = 0;
        REQUIRE_THROWS_WITH((multilevel<3>(serial(), q, 1, c, {}, e)), Contains("padding"));
        REQUIRE_THROWS_WITH((multilevel<3>(serial(), p, 0, c, {}, e)), Contains("components"));
    }
    SECTION("evaluation outside the domain")
    {
        multilevel<3> m(serial(), p, 1, c, {}, e);
        m.fit(std::vector<double>(20, 1.0));
        const double x[3] = {5, 0.5, 0.5};
        double out[1];
        REQUIRE_THROWS_AS(m.evaluate(x, out), std::out_of_range);
    }
}

TEST_CASE("degenerate input has documented results", "[core][errors]")
{
    const auto e = randomPoints<3>(100, 61);
    params p;
    p.maxLevels = 8;
    SECTION("no control points: zero everywhere")
    {
        multilevel<3> m(serial(), p, 3, pointsView<3>(), {}, e);
        const fitReport& r = m.fit({});
        CHECK(r.levels == 0);
        std::vector<double> out;
        m.evaluate(out);
        REQUIRE(out.size() == 300);
        for (double x : out) REQUIRE(x == 0.0);
    }
    SECTION("all control points on one plane")
    {
        p.maxLevels = 14;
        auto c = randomPoints<3>(300, 62);
        for (auto& x : c) x[2] = 0.5;
        const auto v = smoothValues<3>(c, 1);
        multilevel<3> m(serial(), p, 1, c, {}, c);   // evaluated on the plane itself
        const fitReport& r = m.fit(v);
        CHECK(std::isfinite(r.maxResidual));
        std::vector<double> out;
        m.evaluate(out);
        for (std::size_t i = 0; i < out.size(); ++i) REQUIRE_THAT(out[i], Catch::WithinAbs(v[i], 1e-6*maxAbs(v)));
    }
    SECTION("control points on one plane, translated: the whole domain translates")
    {
        // (the affine start about the control points' centre leaves no
        // gradient across the plane; the levels then have nothing to fit)
        auto c = randomPoints<3>(200, 64);
        for (auto& x : c) x[2] = 0.1;
        std::vector<double> v;
        for (std::size_t i = 0; i < c.size(); ++i) { v.push_back(0.1); v.push_back(-0.05); v.push_back(0.02); }
        multilevel<3> m(serial(), p, 3, c, {}, e);
        m.fit(v);
        std::vector<double> out;
        m.evaluate(out);
        for (std::size_t i = 0; i < e.size(); ++i)
        {
            REQUIRE_THAT(out[3*i], Catch::WithinAbs(0.1, 1e-12));
            REQUIRE_THAT(out[3*i + 1], Catch::WithinAbs(-0.05, 1e-12));
            REQUIRE_THAT(out[3*i + 2], Catch::WithinAbs(0.02, 1e-12));
        }
    }
    SECTION("one component's control points on a plane off the others' centre: no gradient across it")
    {
        // x given on the plane z = 0.1 only (a face pushed along it), z on
        // that plane and on z = 0.9 (a face that slides): the affine start's
        // x has no gradient across the plane (the fit about x's own points'
        // centroid), so x translates the whole domain, and the levels have
        // nothing to fit; z is affine between the planes
        auto c = randomPoints<3>(200, 65);
        std::vector<double> v;
        std::vector<std::uint8_t> mask;
        for (std::size_t i = 0; i < c.size(); ++i)
        {
            const bool low = i % 2 == 0;
            c[i][2] = low ? 0.1 : 0.9;
            v.push_back(low ? 0.1 : 0.0);
            v.push_back(0.0);
            v.push_back(low ? 0.2 : 0.0);
            mask.push_back(low);
            mask.push_back(low);
            mask.push_back(1);
        }
        multilevel<3> m(serial(), p, 3, c, mask, e);
        const fitReport& r = m.fit(v);
        CHECK(r.levels == 0);
        std::vector<double> out;
        m.evaluate(out);
        for (std::size_t i = 0; i < e.size(); ++i)
        {
            REQUIRE_THAT(out[3*i], Catch::WithinAbs(0.1, 1e-12));
            REQUIRE_THAT(out[3*i + 1], Catch::WithinAbs(0.0, 1e-12));
            REQUIRE_THAT(out[3*i + 2], Catch::WithinAbs(0.2*(0.9 - e[i][2])/0.8, 1e-12));
        }
    }
    SECTION("collinear control points, affine start")
    {
        std::vector<point<3>> c;
        std::vector<double> v;
        for (int i = 0; i < 50; ++i) { c.push_back({{i/49.0, 0.2, 0.3}}); v.push_back(1 + 2*(i/49.0)); }
        multilevel<3> m(serial(), p, 1, c, {}, c);
        const fitReport& r = m.fit(v);
        CHECK(r.levels == 0);    // a linear field along the line is affine
        std::vector<double> out;
        m.evaluate(out);
        for (std::size_t i = 0; i < out.size(); ++i) REQUIRE_THAT(out[i], Catch::WithinAbs(v[i], 1e-12));
    }
    SECTION("duplicate points with conflicting values: least squares, stops at maxLevels")
    {
        std::vector<point<3>> c = randomPoints<3>(30, 63);
        std::vector<double> v(30, 0.0);
        c.push_back(c[0]);
        v[0] = 1.0;
        v.push_back(3.0);
        multilevel<3> m(serial(), p, 1, c, {}, e);
        const fitReport& r = m.fit(v);
        CHECK(r.levels == p.maxLevels);
        CHECK_FALSE(r.converged);
        std::vector<double> out;
        m.evaluateControl(out);
        CHECK_THAT(out[0], Catch::WithinAbs(2.0, 1e-9));   // the mean of the two
        CHECK(out[0] == out[30]);
        m.evaluate(out);
        for (double x : out) REQUIRE(std::isfinite(x));
    }
    SECTION("a single control point")
    {
        const std::vector<point<3>> c{{{0.5, 0.5, 0.5}}};
        multilevel<3> m(serial(), p, 1, c, {}, pointsView<3>());
        m.fit({4.0});
        double out[1];
        m.evaluate(c[0].data(), out);
        CHECK_THAT(out[0], Catch::WithinAbs(4.0, 1e-14));
    }
}
