// The exchanges of the partial sums on simulated ranks: chunks and the tree
// give the direct exchange's or serial's values, and what a rank receives
// (bytes, messages, which nodes) is bounded as the plan says.
#include "chunkExchange.hpp"
#include "simulatedRanks.hpp"
#include "treeSum.hpp"

#include <catch2/catch.hpp>

#include <map>
#include <set>

using namespace mba;
using namespace bsmTest;

TEST_CASE("chunked exchange: the direct exchange's values, bit for bit, and serial's; on two ranks no fewer values", "[parallel][chunks]")
{
    // a surface (the morphing case) and scattered points
    const bool masked = GENERATE(false, true);
    const bool surface = GENERATE(true, false);
    const partition how = GENERATE(partition::slabs, partition::boxes, partition::random);
    const auto c = surface ? surfacePoints<3>(14) : randomPoints<3>(1500, 75);
    const auto e = randomPoints<3>(1500, 73);
    problem pb;
    pb.p.tolerance = 1e-9;
    pb.p.bucketTiles = 8;
    const std::vector<double> v = smoothValues<3>(c, pb.nc);
    const std::vector<std::uint8_t> mask = masked ? mixedMask(c.size(), pb.nc) : std::vector<std::uint8_t>();
    const std::vector<double> ref = solve<3>(1, how, c, v, mask, e, pb);
    std::int64_t loneOnChunked = 0;    // (lone points on chunked levels: the same on direct ones)
    for (const int P : {2, 3, 5, 8, 16})
    {
        INFO("ranks " << P << ", masked " << masked << ", surface " << surface << ", partition " << name(how));
        std::vector<std::vector<levelStats>> st(P), stDirect(P);
        pb.stats = &st;
        pb.p.exchange = params::exchangeMode::chunked;
        const std::vector<double> chunked = solve<3>(P, how, c, v, mask, e, pb);
        pb.p.exchange = params::exchangeMode::direct;
        pb.stats = &stDirect;
        const std::vector<double> direct = solve<3>(P, how, c, v, mask, e, pb);
        pb.stats = nullptr;
        int chunkedLevels = 0;
        for (const levelStats& s : st[0]) chunkedLevels += s.chunked;
        CHECK(chunkedLevels >= 4);
        if (P == 2)
        {
            // On two ranks no rank receives fewer values in chunks (why
            // `automatic` plans none there): a node a rank reads that the
            // other weighs comes once either way, and as a node's owner it
            // may receive partial sums it does not read
            std::int64_t more = 0;
            for (int r = 0; r < P; ++r)
            {
                REQUIRE(st[r].size() == stDirect[r].size());
                for (std::size_t k = 0; k < st[r].size(); ++k)
                {
                    if (!st[r][k].chunked) continue;
                    CHECK(st[r][k].bytesReceivedPerApply >= stDirect[r][k].bytesReceivedPerApply);
                    more += st[r][k].bytesReceivedPerApply - stDirect[r][k].bytesReceivedPerApply;
                }
            }
            CHECK(more > 0);
            std::vector<std::vector<levelStats>> stAutomatic(P);
            pb.stats = &stAutomatic;
            pb.p.exchange = params::exchangeMode::automatic;
            solve<3>(P, how, c, v, mask, e, pb);
            pb.stats = nullptr;
            for (const auto& rank : stAutomatic)
                for (const levelStats& s : rank) CHECK(!s.chunked);
        }
        for (const auto& rank : st)
            for (const levelStats& s : rank) loneOnChunked += s.chunked ? s.lonePoints : 0;
        std::size_t differ = 0;
        double diff = 0;
        for (std::size_t i = 0; i < ref.size(); ++i)
        {
            differ += !(chunked[i] == direct[i]);
            diff = std::max(diff, std::abs(chunked[i] - ref[i]));
        }
        CHECK(differ == 0);
        CHECK(diff <= 1e-12*maxAbs(v));
    }
    CHECK(loneOnChunked > 0);
}

TEST_CASE("chunked exchange: a rank receives a shared tile's worth, however many ranks share it", "[parallel][chunks]")
{
    // level 0 is one tile that every rank contributes to and reads: directly
    // each rank receives P - 1 tiles; in chunks the other ranks' partial sums
    // of the nodes it sums, then the other nodes summed (two tiles at most)
    const auto c = surfacePoints<3>(20);
    const auto e = randomPoints<3>(3000, 74);
    const auto v = smoothValues<3>(c, 3);
    const std::int64_t tile = tileLayout<3>::nodesPerTile*3*std::int64_t(sizeof(double));
    for (const int P : {4, 8, 16})
    {
        problem pb;
        pb.p.tolerance = 1e-8;
        pb.p.exchange = params::exchangeMode::chunked;
        std::vector<std::vector<levelStats>> st(P);
        pb.stats = &st;
        solve<3>(P, partition::slabs, c, v, {}, e, pb);
        for (int r = 0; r < P; ++r)
        {
            INFO(P << " ranks, rank " << r);
            REQUIRE(st[r][0].chunked);
            CHECK(st[r][0].bytesReceivedPerApply <= 2*tile);
            CHECK(st[r][0].bytesReceivedPerApply >= tile*(P - 1)/P);
        }
    }
}

TEST_CASE("tree sum: the same bits on every rank, one message a round", "[parallel][tree]")
{
    const int P = GENERATE(2, 3, 5, 6, 7, 8, 16);
    const std::size_t n = GENERATE(std::size_t(0), std::size_t(5), std::size_t(1000));
    int p2 = 1;
    while (2*p2 <= P) p2 *= 2;
    int log2p2 = 0;
    while ((1 << log2p2) < p2) ++log2p2;
    std::vector<std::vector<double>> exact(P), rounded(P);
    std::vector<std::uint64_t> received(P);
    runSimulated(P, [&](const communicator& comm) {
        std::mt19937 rng(1000 + unsigned(comm.rank()));
        std::uniform_real_distribution<double> u(-1, 1);
        std::vector<double> a(n), b(n);
        for (std::size_t i = 0; i < n; ++i)
        {
            a[i] = double((i + 1)*(comm.rank() + 1));   // sums exact in any order
            b[i] = u(rng)*std::pow(10.0, int(rng() % 9) - 4);   // sums that depend on the order
        }
        std::vector<double> work;
        const std::uint64_t before = comm.traffic().messagesReceived;
        treeSum(comm, a, work);
        received[comm.rank()] = comm.traffic().messagesReceived - before;
        treeSum(comm, b, work);
        exact[comm.rank()] = a;
        rounded[comm.rank()] = b;
    });
    INFO(P << " ranks, " << n << " values");
    for (std::size_t i = 0; i < n; ++i) REQUIRE(exact[0][i] == double((i + 1)*P*(P + 1)/2));
    for (int r = 0; r < P; ++r)
    {
        INFO("rank " << r);
        CHECK(exact[r] == exact[0]);
        CHECK(rounded[r] == rounded[0]);
        // one message a halving and a doubling round, and one more where P
        // is not a power of two (n = 5 leaves some halves empty: no message)
        CHECK(received[r] <= std::uint64_t(2*log2p2 + (P > p2)));
        if (n >= std::size_t(p2)) CHECK(received[r] >= std::uint64_t(r < p2 ? 2*log2p2 : 1));
    }
}

namespace {

/// The tree exchange on P ranks against serial (1e-12), with at most one
/// message a round on each tree level
template <int D>
void treeEqualsSerial(bool surface, bool masked, partition how, const std::vector<int>& ranks)
{
    const auto c = surface ? surfacePoints<D>(D == 3 ? 14 : 60) : randomPoints<D>(D == 3 ? 1500 : 600, 75);
    const auto e = randomPoints<D>(1500, 73);
    problem pb;
    pb.p.tolerance = 1e-9;
    pb.p.bucketTiles = 8;
    const std::vector<double> v = smoothValues<D>(c, pb.nc);
    const std::vector<std::uint8_t> mask = masked ? mixedMask(c.size(), pb.nc) : std::vector<std::uint8_t>();
    const std::vector<double> ref = solve<D>(1, how, c, v, mask, e, pb);
    for (const int P : ranks)
    {
        INFO("D " << D << ", ranks " << P << ", surface " << surface << ", masked " << masked << ", partition "
             << name(how));
        std::vector<std::vector<levelStats>> st(P);
        pb.stats = &st;
        pb.p.exchange = params::exchangeMode::tree;
        const std::vector<double> tree = solve<D>(P, how, c, v, mask, e, pb);
        int p2 = 1, log2p2 = 0;
        while (2*p2 <= P) p2 *= 2, ++log2p2;
        int treeLevels = 0;
        for (const levelStats& s : st[0]) treeLevels += s.tree;
        CHECK(treeLevels >= 4);
        for (int r = 0; r < P; ++r)
            for (const levelStats& s : st[r])
                if (s.tree) CHECK(s.messagesReceived <= 2*log2p2 + (P > p2));
        double diff = 0;
        for (std::size_t i = 0; i < ref.size(); ++i) diff = std::max(diff, std::abs(tree[i] - ref[i]));
        CHECK(diff <= 1e-12*maxAbs(v));
    }
}

} // namespace

TEST_CASE("tree exchange: serial's values, 2 log2(P) messages a rank on a level", "[parallel][tree]")
{
    const bool surface = GENERATE(true, false);
    const bool masked = GENERATE(false, true);
    const partition how = GENERATE(partition::slabs, partition::boxes, partition::random);
    treeEqualsSerial<3>(surface, masked, how, {2, 3, 5, 8, 16});
    treeEqualsSerial<2>(surface, masked, how, {3, 5});
}

TEST_CASE("automatic exchange: the tree on the coarse levels that 64 slabs share, chunks or direct below", "[parallel][tree]")
{
    // level 0 is one tile that every rank contributes to and reads: directly
    // each rank would receive 63 messages, in chunks 2 x 63, through the
    // tree 12 (in 12 rounds instead of one or two: in the model of
    // levelPlanner::exchangeCost the tree is cheaper from about 40 ranks)
    const auto c = surfacePoints<3>(65);   // every slab holds control points
    const auto e = randomPoints<3>(3000, 74);
    const auto v = smoothValues<3>(c, 3);
    problem pb;
    pb.p.tolerance = 1e-8;
    const std::vector<double> ref = solve<3>(1, partition::slabs, c, v, {}, e, pb);
    const int P = 64;
    std::vector<std::vector<levelStats>> st(P);
    pb.stats = &st;
    const std::vector<double> got = solve<3>(P, partition::slabs, c, v, {}, e, pb);
    for (int r = 0; r < P; ++r)
    {
        INFO("rank " << r);
        REQUIRE(st[r][0].tree);
        CHECK(st[r][0].messagesReceived == 12);
        for (const levelStats& s : st[r]) CHECK(s.tree == st[0][s.level].tree);   // the same choice on every rank
        CHECK(!st[r].back().tree);
    }
    double diff = 0;
    for (std::size_t i = 0; i < ref.size(); ++i) diff = std::max(diff, std::abs(got[i] - ref[i]));
    CHECK(diff <= 1e-12*maxAbs(v));
}

TEST_CASE("each rank receives a small part of the finest level (surface, 8 slabs)", "[parallel]")
{
    const auto c = surfacePoints<3>(60);
    const auto e = randomPoints<3>(20000, 101);
    std::vector<double> v(c.size());
    for (std::size_t i = 0; i < c.size(); ++i) v[i] = smooth<3>(c[i], 0) + std::exp(-40*c[i][1]);
    params p;
    p.tolerance = 1e-8;
    p.maxLevels = 9;
    std::int64_t serialNodes = 0;
    int levels = 0;
    {
        multilevel<3> m(serial(), p, 1, c, {}, e);
        levels = m.fit(v).levels;
        serialNodes = m.stats()[levels - 1].viewTiles*tileLayout<3>::nodesPerTile;
    }
    REQUIRE(levels >= 7);
    const int P = 8;
    const auto rc = ranksOf<3>(c, P, partition::slabs, 1), re = ranksOf<3>(e, P, partition::slabs, 2);
    std::vector<std::int64_t> recv(P), gatherAll(P);
    runSimulated(P, [&](const communicator& comm) {
        std::vector<point<3>> cl, el;
        std::vector<double> vl;
        for (std::size_t i = 0; i < c.size(); ++i)
            if (rc[i] == comm.rank()) { cl.push_back(c[i]); vl.push_back(v[i]); }
        for (std::size_t i = 0; i < e.size(); ++i) if (re[i] == comm.rank()) el.push_back(e[i]);
        multilevel<3> m(comm, p, 1, cl, {}, el);
        const fitReport& r = m.fit(vl);
        REQUIRE(r.levels == levels);
        const levelStats finest = m.stats()[levels - 1];
        recv[comm.rank()] = finest.tilesReceived*tileLayout<3>::nodesPerTile;
        gatherAll[comm.rank()] = m.gatherAllBytes();
    });
    for (int r = 0; r < P; ++r)
    {
        INFO("rank " << r << " receives " << recv[r] << " of " << serialNodes << " finest-level nodes");
        CHECK(recv[r] < serialNodes/4);
        CHECK(gatherAll[r] > 0);
    }
}

namespace {

/// A surface (points on the cube's faces, the morphing case) and scattered
/// evaluation points on P slabs along x (the control points on the first
/// controlRanks of them), fitted with the given exchange: which rank holds
/// each point, and each rank's levels
struct surfaceOnSlabs
{
    const std::vector<point<3>> c = surfacePoints<3>(40), e = randomPoints<3>(8000, 111);
    const std::vector<int> rc, re;
    std::vector<std::vector<levelStats>> stats;
    domain<3> dom;

    surfaceOnSlabs(int P, params::exchangeMode exchange, int controlRanks)
    :
        rc(ranksOf<3>(c, controlRanks, partition::slabs, 1)), re(ranksOf<3>(e, P, partition::slabs, 2)), stats(P)
    {
        const auto v = smoothValues<3>(c, 3);
        params p;
        p.tolerance = 1e-8;
        p.maxLevels = 9;
        p.exchange = exchange;
        runSimulated(P, [&](const communicator& comm) {
            std::vector<point<3>> cl, el;
            std::vector<double> vl;
            for (std::size_t i = 0; i < c.size(); ++i)
                if (rc[i] == comm.rank()) { cl.push_back(c[i]); vl.insert(vl.end(), &v[3*i], &v[3*i] + 3); }
            for (std::size_t i = 0; i < e.size(); ++i) if (re[i] == comm.rank()) el.push_back(e[i]);
            multilevel<3> m(comm, p, 3, cl, {}, el);
            m.fit(vl);
            stats[comm.rank()] = m.stats();
            if (comm.rank() == 0) dom = m.dom();
        });
    }

    /// f(node key, tile key) for each node of x's stencil at level k
    /// (positive: of positive weight; the cubic basis' last weight is 0 on
    /// a knot)
    template <class F>
    void forStencil(int k, const point<3>& x, bool positive, F f) const
    {
        const auto key = [](std::int64_t i, std::int64_t j, std::int64_t l) { return (i*100003 + j)*100019 + l; };
        const double s = std::ldexp(1.0, k);
        const point<3> u = dom.local0(x.data());
        std::int64_t b[3];
        bool knot[3];
        for (int d = 0; d < 3; ++d)
        {
            b[d] = std::int64_t(u[d]*s);
            knot[d] = u[d]*s == double(b[d]);
        }
        for (int a0 = 0; a0 < 4; ++a0)
            for (int a1 = 0; a1 < 4; ++a1)
                for (int a2 = 0; a2 < 4; ++a2)
                {
                    if (positive && ((a0 == 3 && knot[0]) || (a1 == 3 && knot[1]) || (a2 == 3 && knot[2]))) continue;
                    const std::int64_t i = b[0] + a0, j = b[1] + a1, l = b[2] + a2;
                    f(key(i, j, l), key(i/tileEdge, j/tileEdge, l/tileEdge));
                }
    }
};

} // namespace

TEST_CASE("a rank receives per level from each rank the fewer of its points and of its nodes that reach what it reads", "[parallel]")
{
    // A surface on 2, 4 and 8 slabs (surfaceOnSlabs: the direct exchange).
    // On a level, rank r reads the nodes of its points' stencils (control
    // and evaluation points). From each other rank s it receives per apply
    // either the residuals of s's control points whose stencils reach one of
    // those nodes (ghosts) or s's partial sums at those of the nodes where a
    // point of s has weight (tiles), whichever are fewer (tiles on a tie), 3
    // values each; counted here node by node, on every level.
    const int P = GENERATE(2, 4, 8);
    const surfaceOnSlabs run(P, params::exchangeMode::direct, P);
    const auto& c = run.c;
    const auto& e = run.e;
    const auto& rc = run.rc;
    const auto& re = run.re;
    const auto& st = run.stats;
    std::int64_t tileOnly = 0;   // points reaching a tile read, none of its nodes read
    std::int64_t byGhosts = 0, byTiles = 0;   // pairs and levels where values travel each way
    for (int k = 0; k < int(st[0].size()); ++k)
    {
        const auto forStencil = [&](const point<3>& x, bool positive, auto f) { run.forStencil(k, x, positive, f); };
        std::vector<std::set<std::int64_t>> reads(P), readTiles(P), weighs(P);
        for (std::size_t i = 0; i < c.size(); ++i)
        {
            forStencil(c[i], false, [&](std::int64_t n, std::int64_t t) { reads[rc[i]].insert(n); readTiles[rc[i]].insert(t); });
            forStencil(c[i], true, [&](std::int64_t n, std::int64_t) { weighs[rc[i]].insert(n); });
        }
        for (std::size_t i = 0; i < e.size(); ++i)
            forStencil(e[i], false, [&](std::int64_t n, std::int64_t t) { reads[re[i]].insert(n); readTiles[re[i]].insert(t); });
        for (int r = 0; r < P; ++r)
        {
            std::int64_t values = 0, ghosts = 0;
            for (int from = 0; from < P; ++from)
            {
                if (from == r) continue;
                std::int64_t points = 0, nodes = 0;
                for (std::size_t i = 0; i < c.size(); ++i)
                {
                    if (rc[i] != from) continue;
                    bool node = false, tile = false;
                    forStencil(c[i], false, [&](std::int64_t n, std::int64_t t) {
                        node = node || reads[r].count(n) > 0;
                        tile = tile || readTiles[r].count(t) > 0;
                    });
                    points += node;
                    tileOnly += tile && !node;
                }
                for (const std::int64_t n : reads[r]) nodes += std::int64_t(weighs[from].count(n));
                values += std::min(points, nodes);
                if (points < nodes) ghosts += points;
                byGhosts += points < nodes && points > 0;
                byTiles += nodes <= points && nodes > 0;
            }
            INFO(P << " ranks, level " << k << ", rank " << r);
            CHECK(st[r][k].bytesReceivedPerApply == values*3*std::int64_t(sizeof(double)));
            CHECK(st[r][k].ghostsReceived == ghosts);
        }
    }
    CHECK(tileOnly > 0);
    CHECK(byGhosts > 0);
    CHECK(byTiles > 0);
}

TEST_CASE("chunked exchange: a rank receives the summed values of the nodes it reads", "[parallel][chunks]")
{
    // A surface's control points on the first 3 of 4 slabs, evaluation
    // points on all 4 (surfaceOnSlabs), chunked: the last rank contributes
    // nothing, so it owns no chunk and receives only the summed chunks of the
    // tiles it reads, at the nodes its stencils read where a control point
    // has weight, 3 values each; counted here node by node, on every
    // chunked level
    const int P = 4;
    const surfaceOnSlabs run(P, params::exchangeMode::chunked, P - 1);
    const auto& st = run.stats;
    int chunkedLevels = 0, partOfTiles = 0;   // (levels where it reads part of the tiles' weighed nodes)
    for (int k = 0; k < int(st[P - 1].size()); ++k)
    {
        if (!st[P - 1][k].chunked) continue;
        ++chunkedLevels;
        std::set<std::int64_t> reads, readTiles;
        std::map<std::int64_t, std::int64_t> weighed;   // node -> tile
        for (std::size_t i = 0; i < run.e.size(); ++i)
            if (run.re[i] == P - 1)
                run.forStencil(k, run.e[i], false, [&](std::int64_t n, std::int64_t t) { reads.insert(n); readTiles.insert(t); });
        for (const point<3>& x : run.c)
            run.forStencil(k, x, true, [&](std::int64_t n, std::int64_t t) { weighed[n] = t; });
        std::int64_t nodes = 0, tileNodes = 0;   // read and weighed; of the tiles read, weighed
        for (const std::int64_t n : reads) nodes += std::int64_t(weighed.count(n));
        for (const auto& w : weighed) tileNodes += std::int64_t(readTiles.count(w.second));
        INFO("level " << k);
        CHECK(st[P - 1][k].bytesReceivedPerApply == nodes*3*std::int64_t(sizeof(double)));
        partOfTiles += nodes < tileNodes;
    }
    CHECK(chunkedLevels >= 4);
    CHECK(partOfTiles >= 2);
}

TEST_CASE("chunked exchange: each node is summed by a rank whose points weigh it", "[parallel][chunks]")
{
    // A surface on 2, 4 and 8 slabs (surfaceOnSlabs), chunked. A node that
    // the points of the ranks C weigh and the stencils of the ranks R read
    // (C within R: a rank reads its control points' stencils) is summed by
    // one of C: it receives the partial sums of the |C| - 1 others, and each
    // of the |R| - 1 other readers the sum, 3 values each. Whichever of C
    // sums it, the ranks receive that together on a level; a node summed by
    // a rank that does not weigh it costs one value more. Counted here node
    // by node, on every chunked level.
    const int P = GENERATE(2, 4, 8);
    const surfaceOnSlabs run(P, params::exchangeMode::chunked, P);
    const auto& st = run.stats;
    int chunkedLevels = 0;
    for (int k = 0; k < int(st[0].size()); ++k)
    {
        if (!st[0][k].chunked) continue;
        ++chunkedLevels;
        std::map<std::int64_t, std::set<int>> weighs, reads;   // node -> ranks
        for (std::size_t i = 0; i < run.c.size(); ++i)
        {
            run.forStencil(k, run.c[i], true, [&](std::int64_t n, std::int64_t) { weighs[n].insert(run.rc[i]); });
            run.forStencil(k, run.c[i], false, [&](std::int64_t n, std::int64_t) { reads[n].insert(run.rc[i]); });
        }
        for (std::size_t i = 0; i < run.e.size(); ++i)
            run.forStencil(k, run.e[i], false, [&](std::int64_t n, std::int64_t) { reads[n].insert(run.re[i]); });
        std::int64_t values = 0, received = 0;
        for (const auto& w : weighs) values += 3*std::int64_t(w.second.size() - 1 + reads[w.first].size() - 1);
        for (int r = 0; r < P; ++r) received += st[r][k].bytesReceivedPerApply;
        INFO(P << " ranks, level " << k);
        CHECK(received == values*std::int64_t(sizeof(double)));
    }
    CHECK(chunkedLevels >= 4);
}

TEST_CASE("chunk owners: a contributor that reaches the node, shares by load from three contributors on", "[chunks]")
{
    // A tile of 64 nodes and four contributors (ranks 2, 5, 7, 9): nodes
    // 0-15 reached by the first alone, 16-31 by the first two, 32-62 by the
    // last three, node 63 by none
    const int C[4] = {2, 5, 7, 9};
    std::vector<std::uint64_t> reach(64, 0);
    for (int n = 0; n < 16; ++n) reach[n] = 0b0001;
    for (int n = 16; n < 32; ++n) reach[n] = 0b0011;
    for (int n = 32; n < 63; ++n) reach[n] = 0b1110;
    std::vector<std::int64_t> loads(10, 0);
    std::vector<int> owner;
    const auto count = [&](int n0, int n1, int c) { return std::count(owner.begin() + n0, owner.begin() + n1, c); };
    for (const std::uint64_t key : {0, 1, 2, 7})
    {
        INFO("key " << key);
        // even loads: even shares
        loads[5] = loads[7] = loads[9] = 1000;
        nodeOwners(C, 4, 64, key, reach, 1, loads, owner);
        for (int n = 0; n < 63; ++n) CHECK((reach[n] >> owner[n] & 1) == 1);
        CHECK(owner[63] == owner[62]);
        CHECK(count(0, 16, 0) == 16);
        CHECK(count(16, 32, 0) == 8);
        CHECK(count(16, 32, 1) == 8);
        for (int c = 1; c < 4; ++c) CHECK((count(32, 63, c) == 10 || count(32, 63, c) == 11));
        // rank 9 with half the others' load sums most of the nodes that
        // three reach (its weight 563 against 63 each), the others a few
        loads[9] = 500;
        nodeOwners(C, 4, 64, key, reach, 1, loads, owner);
        for (int n = 0; n < 63; ++n) CHECK((reach[n] >> owner[n] & 1) == 1);
        CHECK(count(16, 32, 0) == 8);
        CHECK(count(32, 63, 3) >= 25);
        CHECK(count(32, 63, 3) <= 26);
        CHECK(count(32, 63, 1) >= 2);
        CHECK(count(32, 63, 2) >= 2);
    }
}
