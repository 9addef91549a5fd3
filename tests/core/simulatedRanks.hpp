// Simulated ranks for the core tests: how points are dealt to ranks
// (slabs, boxes, random) and a solve on P simulated ranks
#ifndef BSM_SIMULATED_RANKS_HPP
#define BSM_SIMULATED_RANKS_HPP

#include "testData.hpp"

#include <algorithm>
#include <array>
#include <functional>
#include <limits>

namespace bsmTest {

enum class partition { slabs, random, boxes };

inline const char* name(partition how)
{
    return how == partition::slabs ? "slabs" : how == partition::random ? "random" : "boxes";
}

/// Parts per direction of box-shaped ranks: the most even a >= b (>= c) with a b (c) = P
template <int D>
std::array<int, 3> boxParts(int P)
{
    std::array<int, 3> best{P, 1, 1};
    for (int c = 1; D == 3 ? c*c*c <= P : c == 1; ++c)
        for (int b = c; P % c == 0 && b*b <= P/c; ++b)
            if ((P/c) % b == 0 && P/c/b - c < best[0] - best[2]) best = {P/c/b, b, c};
    return best;
}

/// Rank of point i: slabs along x, boxes (boxParts), or seeded random
template <int D>
std::vector<int> ranksOf(const std::vector<mba::point<D>>& x, int P, partition how, unsigned seed)
{
    std::vector<int> r(x.size());
    std::mt19937 rng(seed);
    const std::array<int, 3> m = boxParts<D>(P);
    for (std::size_t i = 0; i < x.size(); ++i)
    {
        if (how == partition::random) { r[i] = int(rng() % unsigned(P)); continue; }
        if (how == partition::slabs) { r[i] = std::min(P - 1, int(x[i][0]*P)); continue; }
        r[i] = 0;
        for (int d = D - 1; d >= 0; --d) r[i] = r[i]*m[d] + std::min(m[d] - 1, int(x[i][d]*m[d]));
    }
    return r;
}

struct problem
{
    int nc = 3;
    mba::params p;
    bool masked = false;
    std::vector<std::vector<mba::levelStats>>* stats = nullptr;   ///< per rank, when given
    std::vector<std::uint8_t> evaluationMask;                ///< per evaluation point x component (empty: all)
    std::vector<mba::fitReport>* reports = nullptr;               ///< per rank, when given
    /// A trend at the nodes of level trendLevel (-1: none): its coefficient
    /// at node x, component c
    int trendLevel = -1;
    std::function<double(const double* x, int c)> trend;
};

/// The coefficients of a trend of level k for m's fit (node x component):
/// f(x, c) at the nodes m.latticeNodes(k) lists
template <int D, class F>
std::vector<double> trendAtNodes(const mba::multilevel<D>& m, int k, int nc, F&& f)
{
    const std::vector<double> nodes = m.latticeNodes(k);
    std::vector<double> t;
    for (std::size_t i = 0; i < nodes.size(); i += D)
        for (int c = 0; c < nc; ++c) t.push_back(f(&nodes[i], c));
    return t;
}

/// Values at every evaluation point (global order) from P ranks
template <int D>
std::vector<double> solve(int P, partition how, const std::vector<mba::point<D>>& c, const std::vector<double>& v,
                          const std::vector<std::uint8_t>& mask, const std::vector<mba::point<D>>& e, const problem& pb)
{
    const auto rc = ranksOf<D>(c, P, how, 1), re = ranksOf<D>(e, P, how, 2);
    std::vector<double> out(e.size()*pb.nc, std::numeric_limits<double>::quiet_NaN());
    mba::runSimulated(P, [&](const mba::communicator& comm) {
        std::vector<mba::point<D>> cl, el;
        std::vector<double> vl;
        std::vector<std::uint8_t> ml;
        std::vector<std::size_t> eg;
        std::vector<std::uint8_t> eml;
        for (std::size_t i = 0; i < c.size(); ++i)
        {
            if (rc[i] != comm.rank()) continue;
            cl.push_back(c[i]);
            for (int k = 0; k < pb.nc; ++k)
            {
                vl.push_back(v[i*pb.nc + k]);
                if (!mask.empty()) ml.push_back(mask[i*pb.nc + k]);
            }
        }
        for (std::size_t i = 0; i < e.size(); ++i)
        {
            if (re[i] != comm.rank()) continue;
            el.push_back(e[i]);
            eg.push_back(i);
            if (!pb.evaluationMask.empty())
                eml.insert(eml.end(), &pb.evaluationMask[i*pb.nc], &pb.evaluationMask[i*pb.nc] + pb.nc);
        }
        mba::multilevel<D> m(comm, pb.p, pb.nc, cl, ml, el, eml);
        const std::vector<double> t =
            pb.trendLevel >= 0 ? trendAtNodes<D>(m, pb.trendLevel, pb.nc, pb.trend) : std::vector<double>();
        m.fit(vl, pb.trendLevel, t);
        m.fit(vl, pb.trendLevel, t);   // a second apply through the plan
        std::vector<double> o;
        m.evaluate(o);
        if (pb.stats) (*pb.stats)[comm.rank()] = m.stats();
        if (pb.reports) (*pb.reports)[comm.rank()] = m.report();
        for (std::size_t j = 0; j < eg.size(); ++j)
            for (int k = 0; k < pb.nc; ++k) out[eg[j]*pb.nc + k] = o[j*pb.nc + k];   // disjoint writes
    });
    return out;
}

} // namespace bsmTest
#endif
