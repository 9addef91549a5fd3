// Serial multilevel B-spline approximation: invariants, sparsity, plan/apply (bad and
// degenerate input: errorTests.cpp)
#include "flatEvaluator.hpp"
#include "testData.hpp"

#include <catch2/catch.hpp>

#include <limits>

using namespace mba;
using namespace bsmTest;
using Catch::Matchers::Contains;

namespace {


template <int D>
void singlePointReproduced(bool affine)
{
    const std::vector<point<D>> c = randomPoints<D>(1, 7);
    const std::vector<point<D>> e = randomPoints<D>(50, 8);
    params p;
    p.affine = affine;
    p.maxLevels = 1;
    p.tolerance = 0;
    multilevel<D> m(serial(), p, 3, c, {}, e);
    const std::vector<double> v{0.7, -1.3, 2.9};
    m.fit(v);
    std::vector<double> out;
    m.evaluateControl(out);
    for (int k = 0; k < 3; ++k) CHECK_THAT(out[k], Catch::WithinAbs(v[k], 1e-14));
}

template <int D>
void affineReproduced()
{
    const std::vector<point<D>> c = randomPoints<D>(200, 11, -2, 3);
    const std::vector<point<D>> e = randomPoints<D>(500, 12, -2, 3);
    const double a[3] = {0.3, -1.0, 2.0};
    const double B[3][3] = {{1.0, 0.2, -0.5}, {0.0, -0.7, 0.4}, {0.9, 0.1, 0.3}};
    auto g = [&](const point<D>& x, int k) {
        double s = a[k];
        for (int d = 0; d < D; ++d) s += B[k][d]*x[d];
        return s;
    };
    std::vector<double> v;
    for (const auto& x : c) for (int k = 0; k < 3; ++k) v.push_back(g(x, k));
    params p;
    p.tolerance = 1e-12;
    multilevel<D> m(serial(), p, 3, c, {}, e);
    const fitReport& r = m.fit(v);
    CHECK(r.levels == 0);
    std::vector<double> out;
    m.evaluate(out);
    for (std::size_t i = 0; i < e.size(); ++i)
        for (int k = 0; k < 3; ++k) REQUIRE_THAT(out[i*3 + k], Catch::WithinAbs(g(e[i], k), 1e-12));
}

template <int D>
void residualDecreases(bool affine)
{
    const std::vector<point<D>> c = randomPoints<D>(D == 3 ? 3000 : 1000, 21);
    const std::vector<point<D>> e = randomPoints<D>(100, 22);
    const std::vector<double> v = smoothValues<D>(c, 2);
    params p;
    p.tolerance = 1e-10;
    p.maxLevels = 20;
    p.affine = affine;
    multilevel<D> m(serial(), p, 2, c, {}, e);
    const fitReport& r = m.fit(v);
    CHECK(r.converged);
    CHECK(r.maxResidual <= 1e-10*maxAbs(v));
    double prev = r.initialMaxResidual;
    const auto st = m.stats();
    REQUIRE(int(st.size()) >= r.levels);
    for (int k = 0; k < r.levels; ++k)
    {
        INFO("level " << k);
        CHECK(st[k].maxResidual <= prev);
        prev = st[k].maxResidual;
    }
    // the residual reported is the one evaluation gives at the control points
    std::vector<double> out;
    m.evaluateControl(out);
    for (std::size_t i = 0; i < v.size(); ++i) REQUIRE_THAT(out[i], Catch::WithinAbs(v[i], 2e-10*maxAbs(v)));
}

} // namespace

TEST_CASE("one control point is reproduced exactly (Eq. 4)", "[core]")
{
    singlePointReproduced<2>(false);
    singlePointReproduced<3>(false);
    singlePointReproduced<2>(true);
    singlePointReproduced<3>(true);
}

TEST_CASE("affine fields are reproduced everywhere with the affine start", "[core]")
{
    affineReproduced<2>();
    affineReproduced<3>();
}

TEST_CASE("the max residual never grows and reaches 1e-10 on smooth data", "[core]")
{
    const bool affine = GENERATE(true, false);
    residualDecreases<2>(affine);
    residualDecreases<3>(affine);
}

TEST_CASE("sparse storage grows with the surface, not the volume", "[core]")
{
    const auto c = surfacePoints<3>(40);
    const auto e = randomPoints<3>(10, 3);
    params p;
    p.tolerance = 1e-14;
    p.maxLevels = 9;
    multilevel<3> m(serial(), p, 1, c, {}, e);
    m.fit(smoothValues<3>(c, 1));
    const auto st = m.stats();
    REQUIRE(st.size() >= 6);
    for (std::size_t k = 1; k < st.size(); ++k)
    {
        INFO("level " << k);
        const double nk = double(m.dom().nodes(int(k), 0));
        const double dense = nk*nk*nk;
        if (st[k].dense) continue;
        // a band around the 6 faces: a few node layers thick
        CHECK(st[k].nodes < 6*nk*nk*16);
        if (nk > 200) CHECK(st[k].nodes < 0.25*dense);   // 8 layers of 6 faces: 6*8/nk of the volume
        // halving the spacing: about 4x the nodes (surface), never 8x (volume)
        if (!st[k - 1].dense) CHECK(double(st[k].nodes) < 5.0*st[k - 1].nodes);
    }
    CHECK_FALSE(st.back().dense);
}

namespace {

template <int D>
void flatEqualsLevels(int nc)
{
    // Control points on the faces of the box (the morphing case: sparse fine
    // levels) with a sharp feature, evaluation points inside; the planned
    // evaluation (levels 0..flat refined into one plain lattice, then the
    // finer levels) against the level-by-level sum at each point
    std::vector<point<D>> c;
    for (const auto& x : randomPoints<D>(3000, 41))
    {
        point<D> y = x;
        y[0] = x[0] < 0.5 ? 0.0 : 1.0;
        c.push_back(y);
    }
    // (a number of evaluation points that the wide kernels' blocks of four
    // points do not divide: the last block is partial)
    const auto e = randomPoints<D>(3999, 42);
    const std::vector<double> v3 = smoothValues<D>(c, 3);
    std::vector<double> v;
    for (std::size_t i = 0; i < c.size(); ++i)
        for (int k = 0; k < nc; ++k) v.push_back(v3[3*i + k] + (k == 0 ? std::exp(-200*std::pow(c[i][1] - 0.4, 2)) : 0.0));
    params p;
    p.tolerance = 1e-10;
    multilevel<D> m(serial(), p, nc, c, {}, e);
    const fitReport& r = m.fit(v);
    REQUIRE(r.levels >= 6);
    std::vector<double> planned;
    m.evaluate(planned);
    double scale = 0;
    for (double x : planned) scale = std::max(scale, std::abs(x));
    REQUIRE(scale > 0.1);
    for (std::size_t i = 0; i < e.size(); ++i)
    {
        double one[3];
        m.evaluate(e[i].data(), one);
        for (int k = 0; k < nc; ++k) REQUIRE_THAT(planned[nc*i + k], Catch::WithinAbs(one[k], 1e-12*scale));
    }
}

} // namespace

TEST_CASE("planned evaluation (flat lattice + finer levels) equals the sum of the levels", "[core]")
{
    // with the two-double kernels and, where the processor has AVX2 and FMA,
    // the four-double ones; 1 to 3 components
    for (const bool w : {false, true})
    {
        const bsmTest::vectorWidth width(w);
        INFO("wide vectors " << wideVectors());
        for (int nc = 1; nc <= 3; ++nc)
        {
            INFO(nc << " components");
            flatEqualsLevels<2>(nc);
            flatEqualsLevels<3>(nc);
        }
    }
}

namespace {

/// The points of c whose stencil at level k (its 4^D nodes from its first
/// node) meets no other point's: no node of theirs is any other point's
template <int D>
std::int64_t alonePoints(const domain<D>& dom, int k, const std::vector<point<D>>& c)
{
    std::vector<mba::index<D>> base;
    for (const point<D>& x : c) base.push_back(levelStencil<D>(dom.local0(x.data()), std::ldexp(1.0, k)).base);
    std::int64_t n = 0;
    for (std::size_t i = 0; i < c.size(); ++i)
    {
        bool alone = true;
        for (std::size_t j = 0; j < c.size() && alone; ++j)
        {
            bool meet = j != i;
            for (int d = 0; d < D; ++d) meet = meet && std::abs(base[i][d] - base[j][d]) <= 3;
            alone = !meet;
        }
        n += alone;
    }
    return n;
}

/// The plan fitted to v1 and then, through the plan, to v2 equals the plain
/// method at the evaluation points and at the control points; returns the
/// plan's level statistics (and its domain in dom, when given)
template <int D>
std::vector<levelStats> equalsPlainMBA(const std::vector<point<D>>& c, const std::vector<std::uint8_t>& mask,
                                       const std::vector<point<D>>& e, domain<D>* dom = nullptr)
{
    params p;
    p.affine = false;
    p.tolerance = 1e-13;
    p.maxLevels = 14;
    multilevel<D> m(serial(), p, 3, c, mask, e);
    std::vector<double> v1 = smoothValues<D>(c, 3), v2 = v1;
    for (double& x : v2) x = 0.4*x*x - x;
    m.fit(v1);
    const fitReport& r = m.fit(v2);
    CHECK(r.converged);
    const double tol = 1e-12*maxAbs(v2);
    std::vector<double> got;
    m.evaluate(got);
    const std::vector<double> ref = plainMBA<D>(m.dom(), r.levels, 3, c, v2, mask, e);
    REQUIRE(got.size() == ref.size());
    for (std::size_t i = 0; i < got.size(); ++i) REQUIRE_THAT(got[i], Catch::WithinAbs(ref[i], tol));
    // (and at the same points unplanned, every 7th)
    for (std::size_t i = 0; i < e.size(); i += 7)
    {
        double one[3];
        m.evaluate(e[i].data(), one);
        for (int j = 0; j < 3; ++j) REQUIRE_THAT(one[j], Catch::WithinAbs(ref[i*3 + j], tol));
    }
    m.evaluateControl(got);
    const std::vector<double> refc = plainMBA<D>(m.dom(), r.levels, 3, c, v2, mask, c);
    for (std::size_t i = 0; i < got.size(); ++i) REQUIRE_THAT(got[i], Catch::WithinAbs(refc[i], tol));
    auto st = m.stats();
    st.resize(r.levels);
    if (dom) *dom = m.dom();
    return st;
}

template <int D>
void separatedLevels(bool masked)
{
    // two faces of a mesh; evaluation points in the volume and next to the
    // control points (their stencils read the separated level)
    std::vector<point<D>> c = twoFaces<D>(D == 3 ? 9 : 17, 0.1, 51);
    std::vector<point<D>> e = randomPoints<D>(400, 52);
    const std::vector<point<D>> near = insideFaces<D>(c, 3, 0.004);
    e.insert(e.end(), near.begin(), near.end());
    std::vector<std::uint8_t> mask = masked ? mixedMask(c.size(), 3) : std::vector<std::uint8_t>();
    INFO("D " << D << ", masked " << masked);
    const std::vector<levelStats> st = equalsPlainMBA<D>(c, mask, e);
    // the last level separates the points (that is why the residual is
    // then 0), the coarse ones do not
    REQUIRE(st.size() >= 4);
    CHECK(st.back().separated);
    CHECK_FALSE(st[st.size() - 3].separated);

    // one more point half a cell of that level from another: not separated
    point<D> x = c[c.size()/2];
    x[0] += 0.5*st.back().h;
    c.push_back(x);
    if (masked) mask.insert(mask.end(), {1, 1, 1});
    domain<D> dom;
    const std::vector<levelStats> close = equalsPlainMBA<D>(c, mask, e, &dom);
    REQUIRE(close.size() >= st.size());
    const int k = int(st.size()) - 1;
    CHECK_FALSE(close[k].separated);
    // but the points whose nodes no other point reaches are lone there (the
    // new point's neighbours are not): phi stored from each alone, and the
    // values above equal the plain method's
    const std::int64_t alone = alonePoints<D>(dom, k, c);
    INFO("points " << c.size() << ", alone at level " << k << ": " << alone);
    CHECK(alone > std::int64_t(c.size())/2);
    CHECK(alone < std::int64_t(c.size()) - 1);
    CHECK(close[k].lonePoints == alone);
    CHECK(st[k].lonePoints == 0);                   // (a separated level has no lone points)
    for (int j = 0; j < k - 2; ++j) CHECK(close[j].lonePoints == alonePoints<D>(dom, j, c));
}

/// Control points in a small cluster (sharing nodes down to fine levels)
/// and a few far from it and from each other: lone from the coarse levels
/// on, where the flat lattice holds their coefficients, to the fine ones,
/// where their tiles hold nothing else. Their values, never stored,
/// equal the plain method's at points near them and everywhere else.
template <int D>
void isolatedLonePoints(bool masked)
{
    std::vector<point<D>> c = randomPoints<D>(30, 61, 0.65, 0.7);
    // three corners of the box, more than four level-3 cells (0.125) from
    // the cluster and from each other along some direction
    std::vector<point<D>> far(3);
    for (std::size_t j = 0; j < far.size(); ++j)
        for (int d = 0; d < D; ++d) far[j][d] = (j == 1 && d == 0) || (j == 2 && d == 1) ? 0.95 : 0.05;
    c.insert(c.end(), far.begin(), far.end());
    // 400 points in the unit box: the flat lattice is level 3 in 3D (its
    // box of about 11^3 nodes is within the 4096 a small set gets, level
    // 4's 19^3 is not) and level 5 in 2D (about 35^2; level 6: 66^2)
    std::vector<point<D>> e = randomPoints<D>(400, 63);
    for (const point<D>& x : far)
        for (const point<D>& dx : randomPoints<D>(8, 64, -0.02, 0.02))
        {
            point<D> y = x;
            for (int d = 0; d < D; ++d) y[d] += dx[d];
            e.push_back(y);
        }
    const std::vector<std::uint8_t> mask = masked ? mixedMask(c.size(), 3) : std::vector<std::uint8_t>();
    INFO("D " << D << ", masked " << masked);
    const std::vector<levelStats> st = equalsPlainMBA<D>(c, mask, e);
    const int flat = D == 3 ? 3 : 5;
    REQUIRE(int(st.size()) > flat + 2);
    CHECK(st[flat].lonePoints == std::int64_t(far.size()));
    // a finer level holds no tile for the lone points' nodes alone
    std::int64_t dropped = 0;
    for (std::size_t k = flat + 1; k < st.size(); ++k)
        if (st[k].lonePoints > 0) dropped += st[k].viewTiles*tileLayout<D>::nodesPerTile - st[k].nodes;
    CHECK(dropped > 0);
}

} // namespace

TEST_CASE("lone points' coefficients, not stored, equal the plain method's", "[core]")
{
    const bool masked = GENERATE(false, true);
    isolatedLonePoints<2>(masked);
    isolatedLonePoints<3>(masked);
}

TEST_CASE("the flat lattice holds a node a point up to 65536 nodes and one per 8 points beyond", "[core]")
{
    CHECK(flatNodeBudget(0) == 4096);
    CHECK(flatNodeBudget(1000) == 4096);
    CHECK(flatNodeBudget(20000) == 20000);
    CHECK(flatNodeBudget(65536) == 65536);
    // 97k points (the twisted cube at 46^3 cells) keep the 43k nodes of level 5
    CHECK(flatNodeBudget(100000) == 65536);
    CHECK(flatNodeBudget(524288) == 65536);
    // 8M points: one node per 8 (level 6 of the cube, 300k nodes, not level 7's 2.25M)
    CHECK(flatNodeBudget(8000000) == 1000000);
}

TEST_CASE("levels that separate the control points equal the plain method", "[core]")
{
    const bool masked = GENERATE(false, true);
    separatedLevels<2>(masked);
    separatedLevels<3>(masked);
}

TEST_CASE("applying new values through the plan equals a fresh fit", "[core]")
{
    const auto c = randomPoints<3>(2000, 31);
    // random evaluation points (evaluated in curve order) and a lattice of
    // them numbered row by row (evaluated in their own order)
    std::vector<point<3>> grid;
    for (int i = 0; i < 15; ++i)
        for (int j = 0; j < 15; ++j)
            for (int k = 0; k < 15; ++k) grid.push_back({{i/14.0, j/14.0, k/14.0}});
    const auto e = GENERATE_COPY(randomPoints<3>(3000, 32), grid);
    std::vector<std::uint8_t> mask(c.size()*2, 1);
    for (std::size_t i = 0; i < c.size(); i += 3) mask[2*i + 1] = 0;
    params p;
    p.tolerance = 1e-9;
    multilevel<3> plan(serial(), p, 2, c, mask, e);
    std::vector<double> v1 = smoothValues<3>(c, 2), v2 = v1;
    for (auto& x : v2) x = 0.3*x*x - x;
    std::vector<double> a, b;
    plan.fit(v1);
    plan.evaluate(a);   // evaluating twice through the plan leaves nothing behind
    plan.fit(v2);
    plan.evaluate(a);
    multilevel<3> fresh(serial(), p, 2, c, mask, e);
    fresh.fit(v2);
    fresh.evaluate(b);
    REQUIRE(a.size() == b.size());
    for (std::size_t i = 0; i < a.size(); ++i) REQUIRE(a[i] == b[i]);
    CHECK(plan.report().levels == fresh.report().levels);
}

TEST_CASE("masked components constrain only what they mask", "[core]")
{
    // points on the plane x=0 constrain only component 0 (a slip plane);
    // component 1 is fixed by another point set
    std::vector<point<3>> c;
    std::vector<std::uint8_t> mask;
    std::vector<double> v;
    const auto inner = randomPoints<3>(400, 41, 0.3, 0.7);
    for (const auto& x : inner) { c.push_back(x); mask.insert(mask.end(), {1, 1}); v.push_back(0.1); v.push_back(0.2); }
    const auto plane = randomPoints<3>(400, 42);
    for (auto x : plane) { x[0] = 0; c.push_back(x); mask.insert(mask.end(), {1, 0}); v.push_back(0.0); v.push_back(123.0); }
    params p;
    p.tolerance = 1e-12;
    p.maxLevels = 14;
    multilevel<3> m(serial(), p, 2, c, mask, pointsView<3>());
    const fitReport& r = m.fit(v);
    CHECK(r.converged);
    std::vector<double> out;
    m.evaluateControl(out);
    for (std::size_t i = 0; i < inner.size(); ++i)
    {
        REQUIRE_THAT(out[2*i], Catch::WithinAbs(0.1, 1e-12));
        REQUIRE_THAT(out[2*i + 1], Catch::WithinAbs(0.2, 1e-12));
    }
    for (std::size_t i = inner.size(); i < c.size(); ++i)
    {
        REQUIRE_THAT(out[2*i], Catch::WithinAbs(0.0, 1e-12));
        CHECK(std::abs(out[2*i + 1] - 123.0) > 1);   // free: not pulled to the ignored value
    }
}

namespace {

template <int D>
void stopsBeforeUnreadLevels()
{
    const slidingWall<D> w(12);
    params p;
    p.tolerance = 1e-12;
    p.maxLevels = 14;
    multilevel<D> full(serial(), p, D, w.c, w.mask, w.e);
    const fitReport rf = full.fit(w.v);
    std::vector<double> ref, out;
    full.evaluate(ref);
    REQUIRE(rf.converged);
    p.stopUnread = true;
    // Every value read: the sliding face's own points read their normal
    // component, which its control points constrain at every level
    {
        multilevel<D> m(serial(), p, D, w.c, w.mask, w.e);
        const fitReport& r = m.fit(w.v);
        CHECK(r.levels == rf.levels);
        CHECK(!r.unread);
        m.evaluate(out);
        CHECK(out == ref);
    }
    // The values the mask reads: no level past the fifth reaches them (the
    // inner points lie 0.25 from the faces, the face's points 1 from the
    // other face's), and they are the full fit's
    multilevel<D> m(serial(), p, D, w.c, w.mask, w.e, w.evaluationMask);
    const fitReport& r = m.fit(w.v);
    INFO("D " << D << ": " << r.levels << " levels, the full fit " << rf.levels);
    CHECK(r.unread);
    CHECK(!r.converged);
    CHECK(r.maxResidual > r.threshold);
    CHECK(r.levels >= 3);
    CHECK(r.levels <= 6);
    CHECK(r.levels < rf.levels);
    m.evaluate(out);
    double diff = 0;
    for (std::size_t i = 0; i < out.size(); ++i)
        if (w.evaluationMask[i]) diff = std::max(diff, std::abs(out[i] - ref[i]));
    // (the same coefficients; the flat lattice may fold fewer levels)
    CHECK(diff <= 1e-14*maxAbs(w.v));
    // Capped at those levels (maxLevels), the fit finds the next unread
    // too (and again at its next fit); capped a level earlier, the next is
    // read: the cap stopped it
    params q = p;
    q.maxLevels = r.levels;
    multilevel<D> capped(serial(), q, D, w.c, w.mask, w.e, w.evaluationMask);
    for (int fit = 0; fit < 2; ++fit)
    {
        const fitReport& rc = capped.fit(w.v);
        CHECK(rc.levels == r.levels);
        CHECK(rc.unread);
    }
    std::vector<double> cappedOut;
    capped.evaluate(cappedOut);
    CHECK(cappedOut == out);
    q.maxLevels = r.levels - 1;
    multilevel<D> early(serial(), q, D, w.c, w.mask, w.e, w.evaluationMask);
    const fitReport& re = early.fit(w.v);
    CHECK(re.levels == r.levels - 1);
    CHECK(!re.unread);
    // the plan keeps no arrays of the level it stopped before (the full
    // fit's holds its lattice there), and the next fit stops there again
    const std::vector<levelStats> st = m.stats(), stFull = full.stats();
    REQUIRE(int(st.size()) == r.levels + 1);
    CHECK(st.back().bytes == 0);
    CHECK(stFull[r.levels].bytes > 0);
    const std::vector<double> first = out;
    CHECK(m.fit(w.v).levels == r.levels);
    m.evaluate(out);
    CHECK(out == first);
    // where the level that stopped the fit is read after all, it counts:
    // one more point just inside the sliding face
    std::vector<point<D>> e = w.e;
    std::vector<std::uint8_t> em = w.evaluationMask;
    e.push_back(w.e.front());
    e.back()[D - 1] += 1e-3;
    em.insert(em.end(), D, 1);
    multilevel<D> near(serial(), p, D, w.c, w.mask, e, em);
    CHECK(near.fit(w.v).levels > r.levels);
}

} // namespace

TEST_CASE("a fit can stop before the levels that no evaluation point reads", "[core]")
{
    stopsBeforeUnreadLevels<2>();
    stopsBeforeUnreadLevels<3>();
}

TEST_CASE("a level's coefficient tiles alone and its full plan mark the nodes where omega is > 0", "[multilevel]")
{
    // (the coefficient tiles alone: what the plan of a new level asks the
    // fit on one rank, to find it unread before planning it in full); omega
    // is > 0 where some control point's weight w has w^2 > 0, found node by
    // node: a sliding wall (a mask, one omega a component) and scattered
    // points (one omega a node), levels 0 to 9
    const bool masked = GENERATE(true, false);
    const slidingWall<3> w(12);
    const std::vector<point<3>> c = masked ? w.c : randomPoints<3>(300, 121);
    controlPoints<3> ctrl(c, 3, masked ? w.mask : std::vector<std::uint8_t>());
    ctrl.classify(serial());
    box<3> b = box<3>::empty();
    for (const point<3>& x : c) b.add(x.data());
    const domain<3> dom = domain<3>::fromBox(b, 1, params().padding);
    ctrl.arrange(dom);
    REQUIRE(ctrl.omegaPerNode == (masked ? 3 : 1));
    const int per = ctrl.omegaPerNode;
    for (int k = 0; k < 10; ++k)
    {
        INFO("masked " << masked << ", level " << k);
        levelPlan<3> alone;
        const levelPlan<3> full = planLevel<3>(k, serial(), dom, ctrl, queryClusters<3>(), 8,
                                               params::exchangeMode::automatic, coefficientTilesOf(alone));
        REQUIRE(full.coefficientNodes.size() == std::size_t(full.view.size())*per);
        REQUIRE(alone.coefficientNodes.size() == std::size_t(alone.view.size())*per);
        // node by node, against every control point's weights
        const tileNodeMasks<3> oracle = positiveWeightNodes<3>(ctrl, full.scale);
        CHECK(!oracle.empty());
        CHECK((markedNodes<3>(full, per) == oracle));
        CHECK((markedNodes<3>(alone, per) == oracle));
        // (and no tile of its own that the plan lacks)
        for (std::int64_t a = 0; a < alone.view.size(); ++a) CHECK(full.view.findKey(alone.view.keyOf(a)) >= 0);
    }
}
