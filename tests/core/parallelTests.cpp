// The distributed algorithm on simulated ranks: equal to serial, bitwise
// consistent, failures collective; and the communicator conformance
// suite for the serial and simulated implementations. (The exchanges'
// own tests: exchangeTests.cpp.)
#include "communicatorConformance.hpp"
#include "levelPlan.hpp"
#include "simulatedRanks.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <numeric>

using namespace mba;
using namespace bsmTest;
using Catch::Matchers::Contains;

namespace {

template <int D>
void serialEqualsRanks(bool affine, bool masked, partition how)
{
    const auto c = randomPoints<D>(D == 3 ? 1500 : 600, 71);
    const auto e = randomPoints<D>(2000, 72);
    problem pb;
    pb.p.affine = affine;
    pb.p.tolerance = 1e-9;
    pb.p.bucketTiles = 8;
    const std::vector<double> v = smoothValues<D>(c, pb.nc);
    const std::vector<std::uint8_t> mask = masked ? mixedMask(c.size(), pb.nc) : std::vector<std::uint8_t>();
    const std::vector<double> ref = solve<D>(1, how, c, v, mask, e, pb);
    const double tol = 1e-12*maxAbs(v);
    for (int P : {2, 3, 5, 8})
    {
        INFO("D " << D << ", ranks " << P << ", affine " << affine << ", masked " << masked
             << ", partition " << name(how));
        const std::vector<double> got = solve<D>(P, how, c, v, mask, e, pb);
        double diff = 0;
        for (std::size_t i = 0; i < ref.size(); ++i) diff = std::max(diff, std::abs(got[i] - ref[i]));
        CHECK(diff <= tol);
    }
}

} // namespace

TEST_CASE("communicator conformance: serial", "[parallel][conformance]")
{
    communicatorConformance(serial());
}

TEST_CASE("communicator conformance: simulated ranks", "[parallel][conformance]")
{
    // (3, 5, 6, 7 and 13: the all-gather's last round carries fewer blocks than it holds)
    const int P = GENERATE(1, 2, 3, 4, 5, 6, 7, 8, 13);
    runSimulated(P, [](const communicator& comm) { communicatorConformance(comm); });
}

TEST_CASE("serial equals simulated ranks", "[parallel]")
{
    const bool affine = GENERATE(true, false);
    const bool masked = GENERATE(false, true);
    const partition how = GENERATE(partition::slabs, partition::boxes, partition::random);
    serialEqualsRanks<2>(affine, masked, how);
    serialEqualsRanks<3>(affine, masked, how);
}

TEST_CASE("a fit that stops before the unread levels: serial equals simulated ranks", "[parallel]")
{
    // (the sliding wall of the serial test; every rank stops at the same level)
    const partition how = GENERATE(partition::slabs, partition::boxes, partition::random);
    const slidingWall<3> w(12);
    problem pb;
    pb.p.tolerance = 1e-12;
    pb.p.maxLevels = 14;
    pb.p.stopUnread = true;
    pb.p.bucketTiles = 8;
    pb.evaluationMask = w.evaluationMask;
    std::vector<fitReport> reports(1);
    pb.reports = &reports;
    const std::vector<double> ref = solve<3>(1, how, w.c, w.v, w.mask, w.e, pb);
    REQUIRE(reports[0].unread);
    const int levels = reports[0].levels;
    // each rank stops after as many levels, unread, with serial's values
    const auto sameAsSerial = [&](const int P)
    {
        reports.assign(P, fitReport());
        const std::vector<double> got = solve<3>(P, how, w.c, w.v, w.mask, w.e, pb);
        for (const fitReport& r : reports)
        {
            CHECK(r.unread);
            CHECK(r.levels == levels);
        }
        double diff = 0;
        for (std::size_t i = 0; i < ref.size(); ++i) diff = std::max(diff, std::abs(got[i] - ref[i]));
        CHECK(diff <= 1e-12*maxAbs(w.v));
    };
    for (int P : {2, 3, 5, 8})
    {
        INFO("ranks " << P << ", partition " << name(how) << ", serial stops after " << levels << " levels");
        sameAsSerial(P);
    }
    // Capped at those levels (maxLevels): every rank finds the next
    // unread, as serial does
    pb.p.maxLevels = levels;
    for (int P : {1, 3, 5})
    {
        INFO("capped at " << levels << " levels, ranks " << P << ", partition " << name(how));
        sameAsSerial(P);
    }
}

TEST_CASE("a level's coefficient tiles alone and its full plan, at the nodes a rank's evaluation points read", "[parallel]")
{
    // (what the plan of a new level asks the fit, to find it unread before
    // planning it in full): per rank, at the nodes of positive weight in its
    // evaluation points' stencils, the coefficient tiles and the full plan
    // mark the nodes and components where some control point of any rank
    // has a weight w with w^2 > 0 (found node by node from all of them),
    // also where only another rank's control points reach them
    const bool masked = GENERATE(true, false);
    const partition how = GENERATE(partition::slabs, partition::boxes, partition::random);
    const slidingWall<3> w(12);
    const std::vector<point<3>> c = masked ? w.c : randomPoints<3>(300, 121);
    const std::vector<std::uint8_t> mask = masked ? w.mask : std::vector<std::uint8_t>();
    const std::vector<point<3>> e = randomPoints<3>(800, 122);
    box<3> b = box<3>::empty();
    for (const point<3>& x : c) b.add(x.data());
    for (const point<3>& x : e) b.add(x.data());
    const domain<3> dom = domain<3>::fromBox(b, 1, params().padding);
    // (the oracle: every control point, on one rank)
    controlPoints<3> all(c, 3, mask);
    all.classify(serial());
    all.arrange(dom);
    std::vector<tileNodeMasks<3>> oracle;
    for (int k = 0; k < 9; ++k) oracle.push_back(positiveWeightNodes<3>(all, std::ldexp(1.0, k)));
    for (const int P : {2, 3, 5})
    {
        INFO("masked " << masked << ", partition " << name(how) << ", ranks " << P);
        const auto rc = ranksOf<3>(c, P, how, 1), re = ranksOf<3>(e, P, how, 2);
        std::vector<std::int64_t> marked(P, 0), differ(P, 0), remote(P, 0);
        runSimulated(P, [&](const communicator& comm) {
            const int me = comm.rank();
            std::vector<point<3>> cl, el;
            std::vector<std::uint8_t> ml;
            for (std::size_t i = 0; i < c.size(); ++i)
                if (rc[i] == me)
                {
                    cl.push_back(c[i]);
                    if (masked) ml.insert(ml.end(), &mask[3*i], &mask[3*i] + 3);
                }
            for (std::size_t i = 0; i < e.size(); ++i) if (re[i] == me) el.push_back(e[i]);
            controlPoints<3> ctrl(cl, 3, ml);
            ctrl.classify(comm);
            ctrl.arrange(dom);
            const queryClusters<3> clusters = clusterQueryPoints<3>(comm, ctrl, el);
            const int per = ctrl.omegaPerNode;
            for (int k = 0; k < 9; ++k)
            {
                levelPlan<3> alone, own;
                const levelPlan<3> full = planLevel<3>(k, comm, dom, ctrl, clusters, 8,
                                                       params::exchangeMode::automatic, coefficientTilesOf(alone));
                // (this rank's own points' alone: the nodes only other ranks reach)
                planLevel<3>(k, serial(), dom, ctrl, queryClusters<3>(), 8, params::exchangeMode::automatic,
                             coefficientTilesOf(own));
                for (const point<3>& x : el)
                {
                    const stencil<3> st = levelStencil<3>(dom.local0(x.data()), full.scale);
                    forEachIndex<3>(st.tiles(), [&](const mba::index<3>& t) {
                        const std::uint64_t nodes = st.nodesIn(t, true);
                        const std::int64_t f = full.view.find(t), a = alone.view.find(t), o = own.view.find(t);
                        for (int j = 0; j < per; ++j)
                        {
                            const std::uint64_t fm = f < 0 ? 0 : full.coefficientNodes[f*per + j] & nodes;
                            const std::uint64_t am = a < 0 ? 0 : alone.coefficientNodes[a*per + j] & nodes;
                            const std::uint64_t om = nodesAt<3>(oracle[k], t, j) & nodes;
                            differ[me] += (fm != om) + (am != om);
                            marked[me] += fm != 0;
                            remote[me] += (fm & ~(o < 0 ? 0 : own.coefficientNodes[o*per + j])) != 0;
                        }
                    });
                }
            }
        });
        for (int r = 0; r < P; ++r)
        {
            INFO("rank " << r);
            CHECK(differ[r] == 0);
            CHECK(marked[r] > 0);
        }
        CHECK(std::accumulate(remote.begin(), remote.end(), std::int64_t(0)) > 0);
    }
}

TEST_CASE("levels that separate all or most control points: serial equals simulated ranks", "[parallel]")
{
    // two faces of a mesh, evaluation points in the volume and next to the
    // faces (their stencils read the separated level, also across ranks);
    // close: one more point half a cell of that level from another, so that
    // the level is not separated but most points are lone there
    const bool masked = GENERATE(false, true);
    const partition how = GENERATE(partition::slabs, partition::random);
    const bool close = GENERATE(false, true);
    std::vector<point<3>> c = twoFaces<3>(13, 0.1, 61);
    std::vector<point<3>> e = randomPoints<3>(600, 62);
    const std::vector<point<3>> near = insideFaces<3>(c, 2, 0.003);
    e.insert(e.end(), near.begin(), near.end());
    problem pb;
    pb.p.tolerance = 1e-12;
    pb.p.bucketTiles = 8;
    std::vector<std::uint8_t> mask = masked ? mixedMask(c.size(), pb.nc) : std::vector<std::uint8_t>();
    int finest = 0;
    {
        // (the finest level used does separate them)
        multilevel<3> m(serial(), pb.p, pb.nc, c, mask, e);
        std::vector<double> vm = smoothValues<3>(c, pb.nc);
        const fitReport& r = m.fit(vm);
        REQUIRE(r.converged);
        finest = r.levels - 1;
        REQUIRE(m.stats()[finest].separated);
        if (close)
        {
            point<3> x = c[c.size()/2];
            x[0] += 0.5*m.stats()[finest].h;
            c.push_back(x);
            if (masked) mask.insert(mask.end(), {1, 1, 1});
        }
    }
    const std::vector<double> v = smoothValues<3>(c, pb.nc);
    std::vector<std::vector<levelStats>> st(5);
    pb.stats = &st;
    const std::vector<double> ref = solve<3>(1, how, c, v, mask, e, pb);
    CHECK(st[0][finest].separated == !close);
    CHECK((st[0][finest].lonePoints > std::int64_t(c.size())/2) == close);
    for (int P : {2, 3, 5})
    {
        INFO("ranks " << P << ", masked " << masked << ", partition " << name(how) << ", close " << close);
        const std::vector<double> got = solve<3>(P, how, c, v, mask, e, pb);
        double diff = 0;
        for (std::size_t i = 0; i < ref.size(); ++i) diff = std::max(diff, std::abs(got[i] - ref[i]));
        CHECK(diff <= 1e-12*maxAbs(v));
        // (slabs: each rank has lone points there, of tiles that no other rank reads)
        std::int64_t lone = 0;
        for (int r = 0; r < P; ++r) lone += st[r][finest].lonePoints;
        if (close && how == partition::slabs) CHECK(lone > std::int64_t(c.size())/4);
    }
}

TEST_CASE("a weight whose square vanishes in omega's sum leaves a point lone: serial equals simulated ranks",
          "[parallel]")
{
    // At level 5, p's last node along x is q's first, where q's weight is
    // (1e-6)^3/6: omega there sums to p's w^2 alone, so p is lone (its part
    // of the level, w r/sum(w^2), is what the plain method gives) and q is
    // not; two corners fix the domain and are lone too. Serially omega is
    // formed only where two points' w^2 are > 0 until the lone points are
    // known, on several ranks up front: the same values either way.
    const int k = 5;
    std::vector<point<3>> c = {{{0, 0, 0}}, {{1, 1, 1}}};
    problem pb;
    pb.p.affine = false;
    pb.p.tolerance = 1e-13;
    pb.p.maxLevels = 14;
    const std::vector<std::uint8_t> all;
    domain<3> dom = multilevel<3>(serial(), pb.p, pb.nc, c, all, c).dom();
    const auto at = [&](double ux, double u) {   // (level-k coordinates)
        point<3> x;
        for (int d = 0; d < 3; ++d) x[d] = dom.lo[d] + (d == 0 ? ux : u)*dom.h0/std::ldexp(1.0, k);
        return x;
    };
    c.push_back(at(10.5, 10.5));
    c.push_back(at(14 - 1e-6, 10.5));
    std::vector<point<3>> e;
    for (const point<3>& dx : randomPoints<3>(300, 81, -0.05, 0.05))
    {
        point<3> x = c[2 + e.size() % 2];
        for (int d = 0; d < 3; ++d) x[d] += dx[d];
        e.push_back(x);
    }
    const std::vector<double> v = smoothValues<3>(c, pb.nc);
    std::vector<std::vector<levelStats>> st(3);
    std::vector<fitReport> rep(3);
    pb.stats = &st;
    pb.reports = &rep;
    const std::vector<double> ref = solve<3>(1, partition::slabs, c, v, all, e, pb);
    REQUIRE(rep[0].converged);
    REQUIRE(rep[0].levels > k);
    CHECK(st[0][k].lonePoints == 3);
    CHECK_FALSE(st[0][k].separated);
    const std::vector<double> plain = plainMBA<3>(dom, rep[0].levels, pb.nc, c, v, all, e);
    const double tol = 1e-12*maxAbs(v);
    for (std::size_t i = 0; i < ref.size(); ++i) REQUIRE_THAT(ref[i], Catch::WithinAbs(plain[i], tol));
    for (int P : {2, 3})
    {
        INFO("ranks " << P);
        const std::vector<double> got = solve<3>(P, partition::slabs, c, v, all, e, pb);
        double diff = 0;
        for (std::size_t i = 0; i < ref.size(); ++i) diff = std::max(diff, std::abs(got[i] - ref[i]));
        CHECK(diff <= tol);
    }
}

TEST_CASE("ranks without control or evaluation points", "[parallel]")
{
    // all control points on rank 0, all evaluation points on the last rank:
    // random points, and two faces whose finest level is separated (rank 0
    // then stores no coefficients for its own reading, and the last rank
    // has only what reaches it; evaluation points next to the faces read it)
    const bool faces = GENERATE(false, true);
    const auto c = faces ? twoFaces<3>(13, 0.1, 83) : randomPoints<3>(800, 81);
    auto e = randomPoints<3>(500, 82);
    if (faces)
    {
        const std::vector<point<3>> near = insideFaces<3>(c, 2, 0.003);
        e.insert(e.end(), near.begin(), near.end());
    }
    const auto v = smoothValues<3>(c, 1);
    params p;
    p.tolerance = faces ? 1e-12 : 1e-10;
    std::vector<double> ref;
    {
        multilevel<3> m(serial(), p, 1, c, {}, e);
        const fitReport& r = m.fit(v);
        m.evaluate(ref);
        if (faces) REQUIRE(m.stats()[r.levels - 1].separated);
    }
    const int P = 3;
    std::vector<double> got;
    runSimulated(P, [&](const communicator& comm) {
        const bool first = comm.rank() == 0, last = comm.rank() == P - 1;
        const std::vector<point<3>> cl = first ? c : std::vector<point<3>>{};
        const std::vector<point<3>> el = last ? e : std::vector<point<3>>{};
        multilevel<3> m(comm, p, 1, cl, {}, el);
        m.fit(first ? v : std::vector<double>{});
        m.fit(first ? v : std::vector<double>{});  // again, with what each rank stores narrowed
        std::vector<double> o;
        m.evaluate(o);
        if (last) got = o;
    });
    INFO("two faces " << faces);
    REQUIRE(got.size() == ref.size());
    for (std::size_t i = 0; i < ref.size(); ++i) REQUIRE_THAT(got[i], Catch::WithinAbs(ref[i], 1e-12*maxAbs(v)));
}

TEST_CASE("a point evaluated on several ranks gets bitwise the same value", "[parallel]")
{
    const auto c = randomPoints<3>(1200, 91);
    const auto shared = randomPoints<3>(300, 92);
    const auto v = smoothValues<3>(c, 3);
    params p;
    p.tolerance = 1e-9;
    p.exchange = GENERATE(params::exchangeMode::direct, params::exchangeMode::chunked, params::exchangeMode::tree);
    INFO("exchange " << int(p.exchange));
    const int P = GENERATE(4, 5);
    std::vector<std::vector<double>> got(P);
    runSimulated(P, [&](const communicator& comm) {
        std::vector<point<3>> cl;
        std::vector<double> vl;
        for (std::size_t i = 0; i < c.size(); ++i)
            if (int(i % P) == comm.rank()) { cl.push_back(c[i]); vl.insert(vl.end(), &v[3*i], &v[3*i] + 3); }
        multilevel<3> m(comm, p, 3, cl, {}, shared);   // every rank evaluates the same points
        m.fit(vl);
        m.evaluate(got[comm.rank()]);
    });
    for (int r = 1; r < P; ++r)
    {
        REQUIRE(got[r].size() == got[0].size());
        for (std::size_t i = 0; i < got[0].size(); ++i) REQUIRE(got[r][i] == got[0][i]);
    }
}

TEST_CASE("bad input on one rank fails every rank with the same message", "[parallel][errors]")
{
    const int P = 3;
    std::vector<std::string> msg(P);
    REQUIRE_THROWS_WITH(runSimulated(P, [&](const communicator& comm) {
        auto c = randomPoints<3>(50, 111 + comm.rank());
        multilevel<3> m(comm, params(), 1, c, {}, c);
        std::vector<double> v(50, 1.0);
        if (comm.rank() == 1) v[7] = std::numeric_limits<double>::infinity();
        try { m.fit(v); }
        catch (const collectiveError& e) { msg[comm.rank()] = e.what(); throw; }
    }), Contains("control value 7") && Contains("rank 1"));
    for (int r = 0; r < P; ++r) CHECK(msg[r] == msg[0]);
    CHECK_FALSE(msg[0].empty());
}
