#include <catch2/catch.hpp>
#include "stencilKernels.hpp"
#include "testData.hpp"

#include <cfenv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>

using namespace mba;

namespace {

/// Fills the stack below the caller with signalling NaNs: what a local array
/// that a function called next leaves unwritten would hold
__attribute__((noinline)) void dirtyStack()
{
    const std::uint64_t bits = 0x7ff0000000000001ull;
    double sNaN;
    std::memcpy(&sNaN, &bits, sizeof sNaN);
    volatile double junk[8192];
    for (volatile double& x : junk) x = sNaN;
}

/// The floating-point exceptions that OpenFOAM traps (FOAM_SIGFPE) raised
/// since the last clearTrapped()
void clearTrapped() { std::feclearexcept(FE_ALL_EXCEPT); }
bool trapped() { return std::fetestexcept(FE_INVALID | FE_OVERFLOW | FE_DIVBYZERO) != 0; }

/// The stencil kernels (whole tile rows, split across tiles along the last
/// direction) against a node-by-node reference, on a sparse layout with
/// absent tiles, for stencils starting at every offset within a tile. Called
/// on a stack of signalling NaNs, the kernels raise no exception that
/// OpenFOAM traps (they compute nothing from memory they did not write)
template <int D, int NC>
void checkKernels(unsigned seed)
{
    constexpr int npt = tileLayout<D>::nodesPerTile;
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> U(-1, 1);
    mba::index<D> nodes;
    nodes.fill(4*tileEdge);
    tileLayout<D> L;
    L.init(nodes, false);
    indexBox<D> tiles;
    tiles.lo.fill(0);
    tiles.hi.fill(3);
    forEachIndex<D>(tiles, [&](const mba::index<D>& t) { if (U(rng) < 0.4) L.findOrInsert(t); });
    std::vector<double> phi(L.size()*npt*NC);
    for (double& x : phi) x = U(rng);

    // Node-by-node: f(tile id, node in tile, weight) for the stencil's nodes in existing tiles
    auto eachNode = [&](const stencil<D>& st, auto&& f) {
        indexBox<D> a;
        a.lo.fill(0);
        a.hi.fill(3);
        forEachIndex<D>(a, [&](const mba::index<D>& i) {
            mba::index<D> t;
            int n = 0;
            double w = 1;
            for (int d = 0; d < D; ++d)
            {
                const std::int64_t j = st.base[d] + i[d];
                t[d] = j/tileEdge;
                n = n*tileEdge + int(j % tileEdge);
                w *= st.w[d][i[d]];
            }
            const std::int64_t id = L.find(t);
            if (id >= 0) f(id, n, w);
        });
    };

    int checked = 0;
    for (int combo = 0; combo < (1 << (2*D)); ++combo)   // every offset in every direction
        for (int rep = 0; rep < 4; ++rep)
        {
            point<D> u;
            for (int d = 0; d < D; ++d)
                u[d] = tileEdge*double(rng() % 3) + ((combo >> (2*d)) & 3) + 0.5*(U(rng) + 1);
            const stencil<D> st(u.data());
            stencilTiles<D> tid;
            if (!findTiles(L, st, tid)) continue;
            ++checked;

            double ref[NC] = {}, got[NC] = {};
            eachNode(st, [&](std::int64_t id, int n, double w) {
                for (int k = 0; k < NC; ++k) ref[k] += w*phi[(id*npt + n)*NC + k];
            });
            dirtyStack();
            clearTrapped();
            evalStencil(phi.data(), NC, tid, st, got);
            REQUIRE_FALSE(trapped());
            for (int k = 0; k < NC; ++k) REQUIRE_THAT(got[k], Catch::WithinAbs(ref[k], 1e-14));

            double r[NC];
            for (double& x : r) x = U(rng);
            std::vector<double> a(phi.size(), 0.0), b(phi.size(), 0.0);
            dirtyStack();
            clearTrapped();
            detail::scatterStencil<D, NC>(a.data(), tid, st, r);
            REQUIRE_FALSE(trapped());
            eachNode(st, [&](std::int64_t id, int n, double w) {
                for (int k = 0; k < NC; ++k) b[(id*npt + n)*NC + k] += w*r[k];
            });
            double diff = 0;
            for (std::size_t j = 0; j < a.size(); ++j) diff = std::max(diff, std::abs(a[j] - b[j]));
            REQUIRE(diff <= 1e-15);

            // A run of points in the same cell (the same stencil nodes), up
            // to a few of scatterRun's chunks long
            const int nRun = 1 + int(rng() % 40);
            std::vector<stencil<D>> run;
            std::vector<double> rs;
            for (int j = 0; j < nRun; ++j)
            {
                point<D> v;
                for (int d = 0; d < D; ++d) v[d] = double(st.base[d]) + 0.4999*(U(rng) + 1);
                run.emplace_back(v.data());
                for (int k = 0; k < NC; ++k) rs.push_back(U(rng));
            }
            std::fill(a.begin(), a.end(), 0.0);
            std::fill(b.begin(), b.end(), 0.0);
            dirtyStack();
            clearTrapped();
            detail::scatterRun<D, NC>(a.data(), tid, run.data(), rs.data(), nRun);
            REQUIRE_FALSE(trapped());
            for (int j = 0; j < nRun; ++j)
                eachNode(run[j], [&](std::int64_t id, int n, double w) {
                    for (int k = 0; k < NC; ++k) b[(id*npt + n)*NC + k] += w*rs[j*NC + k];
                });
            diff = 0;
            for (std::size_t j = 0; j < a.size(); ++j) diff = std::max(diff, std::abs(a[j] - b[j]));
            REQUIRE(diff <= 1e-14);
        }
    REQUIRE(checked > (1 << (2*D)));
}

} // namespace

TEST_CASE("tile-row stencil kernels equal a node-by-node reference", "[core][lattice]")
{
    // the two-double kernels and, where the processor has AVX2 and FMA, the
    // four-double ones (wideVectors)
    const unsigned seed = GENERATE(1u, 2u, 3u);
    const bsmTest::vectorWidth width(GENERATE(false, true));
    INFO("wide vectors " << wideVectors());
    SECTION("2D") { checkKernels<2, 1>(seed); checkKernels<2, 2>(seed); checkKernels<2, 3>(seed); }
    SECTION("3D") { checkKernels<3, 1>(seed); checkKernels<3, 2>(seed); checkKernels<3, 3>(seed); }
}
