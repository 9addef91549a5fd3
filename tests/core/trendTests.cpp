// A trend under the levels (multilevel::fit with a trend) and the thin-plate
// spline that samples one (rbf::thinPlateTrend): what the fit subtracts and
// the evaluation adds back, the nodes it is given at, decomposition
// independence, the subset of centres, bad input
#include "simulatedRanks.hpp"
#include "thinPlateTrend.hpp"

#include <catch2/catch.hpp>

#include <set>

using namespace mba;
using namespace bsmTest;
using Catch::Matchers::Contains;

namespace {

/// A smooth trend, component c (not a polynomial: the B-splines do not
/// reproduce it)
template <int D>
double wave(const double* x, int c)
{
    double s = 0.3*std::cos(1.9*x[0] - 0.4*c) + 0.2*x[1]*x[1];
    if (D == 3) s += 0.25*std::sin(2.3*x[2] + c);
    return s;
}

/// The cubic B-spline of level k whose coefficient at every node is f at the
/// node, at x: the oracle of the trend, written out
template <int D, class F>
double bsplineOf(const domain<D>& dom, int k, F&& f, const double* x, int c)
{
    const double h = std::ldexp(dom.h0, -k);
    double w[D][4];
    std::int64_t base[D];
    for (int d = 0; d < D; ++d)
    {
        const double u = (x[d] - dom.lo[d])/h;
        base[d] = std::int64_t(std::floor(u));
        const double s = u - double(base[d]);
        w[d][0] = (1 - s)*(1 - s)*(1 - s)/6;
        w[d][1] = (3*s*s*s - 6*s*s + 4)/6;
        w[d][2] = (-3*s*s*s + 3*s*s + 3*s + 1)/6;
        w[d][3] = s*s*s/6;
    }
    double sum = 0;
    for (int a = 0; a < (1 << 2*D); ++a)
    {
        double wt = 1, node[D];
        for (int d = 0; d < D; ++d)
        {
            const int at = (a >> 2*d) & 3;
            wt *= w[d][at];
            node[d] = dom.lo[d] + double(base[d] + at - 1)*h;   // node j at lo + (j - 1) h
        }
        sum += wt*f(node, c);
    }
    return sum;
}

/// An affine field's coefficients: the B-splines reproduce it exactly, so
/// with it as the trend no level is needed, and the evaluation is the field
template <int D>
void affineTrendReproduced(int k)
{
    const auto c = randomPoints<D>(300, 301, -1, 2);
    const auto e = randomPoints<D>(500, 302, -1, 2);
    auto g = [](const double* x, int j) { return 0.2 - 0.1*j + 0.7*x[0] - (0.3 + j)*x[1] + (D == 3 ? 0.4*x[2] : 0.0); };
    std::vector<double> v;
    for (const auto& x : c) for (int j = 0; j < 3; ++j) v.push_back(g(x.data(), j));
    params p;
    p.affine = false;
    p.tolerance = 1e-12;
    multilevel<D> m(serial(), p, 3, c, {}, e);
    const fitReport& r = m.fit(v, k, trendAtNodes<D>(m, k, 3, g));
    INFO("D " << D << ", trend level " << k);
    CHECK(r.levels == 0);
    CHECK(r.initialMaxResidual <= 1e-12);
    std::vector<double> out;
    m.evaluate(out);
    for (std::size_t i = 0; i < e.size(); ++i)
        for (int j = 0; j < 3; ++j) REQUIRE_THAT(out[i*3 + j], Catch::WithinAbs(g(e[i].data(), j), 1e-12));
}

/// A fit over a trend T equals T plus the plain fit of what T leaves at the
/// control points, at the planned evaluation points (the flat lattice, at
/// the trend's level or finer), at other points and at the control points
template <int D>
void trendPlusFit(int k, bool affine)
{
    const auto c = randomPoints<D>(D == 3 ? 1500 : 600, 311);
    const auto e = randomPoints<D>(D == 3 ? 400 : 200, 312);
    const std::vector<double> v = smoothValues<D>(c, 2);
    params p;
    p.affine = affine;
    p.tolerance = 1e-8;
    multilevel<D> m(serial(), p, 2, c, {}, e);
    const domain<D>& dom = m.dom();
    auto T = [&](const double* x, int j) { return bsplineOf<D>(dom, k, wave<D>, x, j); };
    std::vector<double> left(v);
    for (std::size_t i = 0; i < c.size(); ++i)
        for (int j = 0; j < 2; ++j) left[i*2 + j] -= T(c[i].data(), j);
    multilevel<D> plain(serial(), p, 2, c, {}, e);
    const fitReport& rp = plain.fit(left);
    const fitReport& r = m.fit(v, k, trendAtNodes<D>(m, k, 2, wave<D>));
    INFO("D " << D << ", trend level " << k << ", affine " << affine);
    CHECK(r.levels == rp.levels);
    CHECK(r.converged);
    std::vector<double> out, ref, ctrl;
    m.evaluate(out);
    plain.evaluate(ref);
    const double tol = 1e-12*(1 + maxAbs(v));
    for (std::size_t i = 0; i < e.size(); ++i)
        for (int j = 0; j < 2; ++j) REQUIRE_THAT(out[i*2 + j], Catch::WithinAbs(ref[i*2 + j] + T(e[i].data(), j), tol));
    // (points that were not planned: the levels' tiles point by point)
    const auto x = randomPoints<D>(50, 313);
    for (const auto& xi : x)
    {
        double a[2], b[2];
        m.evaluate(xi.data(), a);
        plain.evaluate(xi.data(), b);
        for (int j = 0; j < 2; ++j) REQUIRE_THAT(a[j], Catch::WithinAbs(b[j] + T(xi.data(), j), tol));
    }
    m.evaluateControl(ctrl);
    for (std::size_t i = 0; i < v.size(); ++i) REQUIRE_THAT(ctrl[i], Catch::WithinAbs(v[i], 2e-8*maxAbs(v)));
    // the same plan without the trend again: the plain fit
    m.fit(left);
    m.evaluate(out);
    for (std::size_t i = 0; i < out.size(); ++i) REQUIRE(out[i] == ref[i]);
}

/// The least (squared distance to its cell's centre, coordinates) per cell
/// of the grid and class, found point by point: the centres the trend must
/// pass through
template <int D>
std::vector<std::size_t> nearestPerCell(const std::vector<point<D>>& c, const std::vector<std::uint8_t>& cls,
                                        const box<D>& b, int grid)
{
    double ext = 0;
    for (int d = 0; d < D; ++d) ext = std::max(ext, b.hi[d] - b.lo[d]);
    const double edge = ext/grid;
    std::map<std::pair<std::vector<long>, int>, std::size_t> best;
    auto keyOf = [&](std::size_t i, std::vector<long>& cell) {
        std::vector<double> k{0};
        cell.assign(D, 0);
        for (int d = 0; d < D; ++d)
        {
            const long n = std::max(1L, long(std::ceil((b.hi[d] - b.lo[d])/edge - 1e-9)));
            cell[d] = std::min(n - 1, long(std::floor((c[i][d] - b.lo[d])/edge)));
            const double r = c[i][d] - (b.lo[d] + (cell[d] + 0.5)*edge);
            k[0] += r*r;
            k.push_back(c[i][d]);
        }
        return k;
    };
    for (std::size_t i = 0; i < c.size(); ++i)
    {
        std::vector<long> cell;
        const std::vector<double> k = keyOf(i, cell);
        const auto key = std::make_pair(cell, int(cls.empty() ? 0 : cls[i]));
        const auto it = best.find(key);
        std::vector<long> other;
        if (it == best.end() || k < keyOf(it->second, other)) best[key] = i;
    }
    std::vector<std::size_t> chosen;
    for (const auto& kv : best) chosen.push_back(kv.second);
    return chosen;
}

} // namespace

TEST_CASE("a trend of an affine field's coefficients reproduces the field with no level", "[core][trend]")
{
    for (int k : {0, 2, 4})
    {
        affineTrendReproduced<2>(k);
        affineTrendReproduced<3>(k);
    }
}

TEST_CASE("a fit over a trend is the trend plus the plain fit of what it leaves", "[core][trend]")
{
    const bool affine = GENERATE(true, false);
    // (level 1: coarser than the flat lattice; 4: finer, the flat lattice
    // made at its level)
    for (int k : {1, 4})
    {
        trendPlusFit<2>(k, affine);
        trendPlusFit<3>(k, affine);
    }
}

TEST_CASE("a fit over a trend: serial equals simulated ranks", "[parallel][trend]")
{
    const partition how = GENERATE(partition::slabs, partition::boxes, partition::random);
    const auto c = randomPoints<3>(1500, 321);
    const auto e = randomPoints<3>(2000, 322);
    problem pb;
    pb.p.tolerance = 1e-9;
    pb.p.bucketTiles = 8;
    pb.trendLevel = 3;
    pb.trend = wave<3>;
    const std::vector<double> v = smoothValues<3>(c, pb.nc);
    const std::vector<double> ref = solve<3>(1, how, c, v, {}, e, pb);
    for (int P : {2, 3, 5, 8})
    {
        INFO("ranks " << P << ", partition " << name(how));
        const std::vector<double> got = solve<3>(P, how, c, v, {}, e, pb);
        double diff = 0;
        for (std::size_t i = 0; i < ref.size(); ++i) diff = std::max(diff, std::abs(got[i] - ref[i]));
        CHECK(diff <= 1e-12*maxAbs(v));
    }
}

TEST_CASE("a trend's bad input gets a clear error", "[core][trend][errors]")
{
    const auto c = randomPoints<3>(100, 331);
    const auto e = randomPoints<3>(100, 332);
    const std::vector<double> v = smoothValues<3>(c, 3);
    multilevel<3> m(serial(), params(), 3, c, {}, e);
    std::vector<double> t = trendAtNodes<3>(m, 2, 3, wave<3>);
    CHECK(t.size() == 7*7*7*3);   // (4 cells a direction at level 2, and 3 nodes more)
    CHECK_THROWS_WITH(m.fit(v, 2, std::vector<double>(t.begin(), t.end() - 1)),
                      Contains("1028 trend coefficients, expected 1029 (level 2 nodes x components)"));
    t[17] = std::nan("");
    CHECK_THROWS_WITH(m.fit(v, 2, t), Contains("trend coefficient 17 is not finite"));
    CHECK_THROWS_WITH(m.fit(v, 17, t), Contains("the trend's level must be in [0, 16], got 17"));
    CHECK_THROWS_WITH(m.latticeNodes(-1), Contains("the trend's level must be in [0, 16], got -1"));
}

TEST_CASE("the thin-plate trend passes through the point nearest each cell's centre, per class", "[rbf][trend]")
{
    // a cube's faces and a sheet of points near its top (a second class)
    std::vector<point<3>> c = surfacePoints<3>(12);
    const std::size_t nFace = c.size();
    for (const auto& x : randomPoints<3>(200, 341, 0.1, 0.9)) c.push_back(point<3>{{x[0], x[1], 0.93}});
    std::vector<std::uint8_t> cls(c.size(), 0);
    std::fill(cls.begin() + nFace, cls.end(), 1);
    const std::vector<double> v = smoothValues<3>(c, 3);
    box<3> b;
    b.lo = point<3>{{-0.01, -0.01, -0.01}};
    b.hi = point<3>{{1.01, 1.01, 1.01}};
    for (const bool classes : {true, false})
    {
        const std::vector<std::uint8_t> k = classes ? cls : std::vector<std::uint8_t>();
        const std::vector<std::size_t> chosen = nearestPerCell<3>(c, k, b, 6);
        // sampled at the chosen points, then at all
        std::vector<point<3>> x;
        for (const std::size_t i : chosen) x.push_back(c[i]);
        x.insert(x.end(), c.begin(), c.end());
        rbf::thinPlateTrend<3> t(serial(), 3, c, {}, k, b, 6, x);
        INFO("classes " << classes);
        CHECK(t.centres() == long(chosen.size()));
        CHECK(t.systems() == 1);
        std::vector<double> out;
        t.sample(v, out);
        for (std::size_t q = 0; q < chosen.size(); ++q)
            for (int j = 0; j < 3; ++j) REQUIRE_THAT(out[q*3 + j], Catch::WithinAbs(v[chosen[q]*3 + j], 1e-9));
        // and not through the others
        double off = 0;
        for (std::size_t i = 0; i < v.size(); ++i) off = std::max(off, std::abs(out[chosen.size()*3 + i] - v[i]));
        CHECK(off > 1e-4);
        // the kept basis gives what the spline gives point by point
        rbf::params p;
        p.function = rbf::kernel::thinPlateSpline;
        const std::vector<point<3>> centres(x.begin(), x.begin() + chosen.size());
        rbf::interpolant<3> direct(serial(), p, 3, centres);
        std::vector<double> vc, ref;
        for (const std::size_t i : chosen) vc.insert(vc.end(), &v[i*3], &v[i*3] + 3);
        direct.fit(vc);
        direct.evaluate(x, ref);
        for (std::size_t i = 0; i < ref.size(); ++i) REQUIRE_THAT(out[i], Catch::WithinAbs(ref[i], 1e-12));
    }
    // the sheet's class adds the sheet's cells: 6 x 6 cells at its height, less those the
    // faces' points already fill (the sheet lies inside the top layer of cells)
    rbf::thinPlateTrend<3> with(serial(), 3, c, {}, cls, b, 6, c), without(serial(), 3, c, {}, {}, b, 6, c);
    CHECK(with.centres() > without.centres());
}

TEST_CASE("the thin-plate trend reproduces affine motion and per-component subsets", "[rbf][trend]")
{
    const auto c = surfacePoints<3>(10);
    const auto e = randomPoints<3>(300, 351);
    auto g = [](const point<3>& x, int j) { return 0.1*j + (j + 1)*0.3*x[0] - 0.2*x[1] + 0.05*j*x[2]; };
    std::vector<double> v;
    for (const auto& x : c) for (int j = 0; j < 3; ++j) v.push_back(g(x, j));
    // component 1 constrained on half the points: its own system
    std::vector<std::uint8_t> mask(c.size()*3, 1);
    for (std::size_t i = 0; i < c.size(); i += 2) mask[i*3 + 1] = 0;
    box<3> b;
    b.lo = point<3>{{0, 0, 0}};
    b.hi = point<3>{{1, 1, 1}};
    rbf::thinPlateTrend<3> t(serial(), 3, c, mask, {}, b, 4, e);
    CHECK(t.systems() == 2);
    std::vector<double> out;
    t.sample(v, out);
    for (std::size_t i = 0; i < e.size(); ++i)
        for (int j = 0; j < 3; ++j) REQUIRE_THAT(out[i*3 + j], Catch::WithinAbs(g(e[i], j), 1e-9));
}

TEST_CASE("the thin-plate trend: serial equals simulated ranks bit for bit", "[rbf][trend][parallel]")
{
    const auto c = surfacePoints<3>(14);
    const auto x = randomPoints<3>(400, 361);
    const std::vector<double> v = smoothValues<3>(c, 3);
    std::vector<std::uint8_t> cls(c.size());
    for (std::size_t i = 0; i < c.size(); ++i) cls[i] = c[i][2] > 0.99;
    box<3> b;
    b.lo = point<3>{{0, 0, 0}};
    b.hi = point<3>{{1, 1, 1}};
    std::vector<double> ref;
    rbf::thinPlateTrend<3>(serial(), 3, c, {}, cls, b, 8, x).sample(v, ref);
    for (int P : {2, 3, 5})
    {
        const auto rc = ranksOf<3>(c, P, partition::random, 3);
        std::vector<std::vector<double>> got(P);
        runSimulated(P, [&](const communicator& comm) {
            std::vector<point<3>> cl;
            std::vector<double> vl;
            std::vector<std::uint8_t> kl;
            for (std::size_t i = 0; i < c.size(); ++i)
            {
                if (rc[i] != comm.rank()) continue;
                cl.push_back(c[i]);
                kl.push_back(cls[i]);
                vl.insert(vl.end(), &v[i*3], &v[i*3] + 3);
            }
            rbf::thinPlateTrend<3> t(comm, 3, cl, {}, kl, b, 8, x);
            t.sample(vl, got[comm.rank()]);
        });
        INFO("ranks " << P);
        for (int r = 0; r < P; ++r) CHECK(got[r] == ref);
    }
}

TEST_CASE("the thin-plate trend's bad input gets a clear error", "[rbf][trend][errors]")
{
    const auto c = surfacePoints<3>(5);
    box<3> b;
    b.lo = point<3>{{0, 0, 0}};
    b.hi = point<3>{{1, 1, 1}};
    CHECK_THROWS_WITH(rbf::thinPlateTrend<3>(serial(), 3, c, {}, {}, b, 0, c),
                      Contains("the trend's grid must be in [1, 32], got 0"));
    CHECK_THROWS_WITH(rbf::thinPlateTrend<3>(serial(), 3, c, {}, std::vector<std::uint8_t>(3), b, 4, c),
                      Contains("3 classes, expected 150"));
    CHECK_THROWS_WITH(rbf::thinPlateTrend<3>(serial(), 3, c, std::vector<std::uint8_t>(7), {}, b, 4, c),
                      Contains("the mask has 7 entries, expected 450"));
    // a basis of 98 centres (the 5 x 5 x 5 grid's surface) + 4 terms at 2^19 points: 408 MB
    const auto many = randomPoints<3>(1 << 19, 371);
    CHECK_THROWS_WITH(rbf::thinPlateTrend<3>(serial(), 3, c, {}, {}, b, 32, many),
                      Contains("basis at its 524288 sample points would take 408 MB (at most 256)"));
    // component 2 constrained on the oblique plane x = y alone: no linear
    // polynomial through it
    std::vector<std::uint8_t> mask(c.size()*3, 1);
    for (std::size_t i = 0; i < c.size(); ++i) mask[i*3 + 2] = c[i][0] == c[i][1];
    CHECK_THROWS_WITH(rbf::thinPlateTrend<3>(serial(), 3, c, mask, {}, b, 4, c),
                      Contains("singular") && Contains("centres for component 2") && Contains("in one plane"));
    // on the face z = 0 alone (a wall it slides on): a spline in the plane
    for (std::size_t i = 0; i < c.size(); ++i) mask[i*3 + 2] = c[i][2] == 0;
    CHECK_NOTHROW(rbf::thinPlateTrend<3>(serial(), 3, c, mask, {}, b, 4, c));
}
