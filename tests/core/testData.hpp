// Seeded test data for the core tests
#ifndef BSM_TEST_DATA_HPP
#define BSM_TEST_DATA_HPP

#include "lattice.hpp"
#include "levelPlan.hpp"
#include "multilevel.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <random>
#include <vector>

namespace bsmTest {

/// The kernels' vector width (mba::useWideVectors) for a scope, restored when
/// the scope ends, also when a failed assertion ends it
struct vectorWidth
{
    const bool was;
    explicit vectorWidth(bool wide) : was(mba::useWideVectors(wide)) {}
    ~vectorWidth() { mba::useWideVectors(was); }
};

/// Per tile and omega value (the component j where a node holds one omega
/// per component, else 0): key {tile coordinates..., j}, the nodes of the
/// tile (bit n: node n, the last direction fastest)
template <int D>
using tileNodeMasks = std::map<std::array<std::int64_t, D + 1>, std::uint64_t>;

/// The key of tile t, omega value j, in tileNodeMasks
template <int D>
std::array<std::int64_t, D + 1> tileNodeKey(const mba::index<D>& t, int j)
{
    std::array<std::int64_t, D + 1> key;
    std::copy(t.begin(), t.end(), key.begin());
    key[D] = j;
    return key;
}

/// The nodes of the level of scale s where a control point of ctrl has a
/// weight w with w*w > 0, its weights multiplied in the order of the
/// directions as the plan multiplies them, found node by node (the oracle of
/// the plan's coefficient nodes: omega, a sum of w^2, is > 0 there)
template <int D>
tileNodeMasks<D> positiveWeightNodes(const mba::controlPoints<D>& ctrl, double s)
{
    tileNodeMasks<D> nodes;
    const int per = ctrl.omegaPerNode;
    ctrl.forEachStencil(s, [&](std::size_t i, const mba::stencil<D>& st) {
        for (int a = 0; a < (1 << 2*D); ++a)
        {
            double w = 1;
            std::array<std::int64_t, D + 1> key;
            int n = 0;
            for (int d = 0; d < D; ++d)
            {
                const int at = (a >> 2*(D - 1 - d)) & 3;
                w = d == 0 ? st.w[0][at] : w*st.w[d][at];
                const std::int64_t x = st.base[d] + at;
                key[d] = x/mba::tileEdge;
                n = n*mba::tileEdge + int(x % mba::tileEdge);
            }
            if (!(w*w > 0)) continue;
            for (int j = 0; j < per; ++j)
            {
                if (per > 1 && !ctrl.mask[i*ctrl.nComponents + j]) continue;
                key[D] = j;
                nodes[key] |= std::uint64_t(1) << n;
            }
        }
    });
    return nodes;
}

/// What a plan's coefficientNodes mark (per omega value of per), as
/// positiveWeightNodes gives it
template <int D>
tileNodeMasks<D> markedNodes(const mba::levelPlan<D>& L, int per)
{
    tileNodeMasks<D> nodes;
    for (std::int64_t id = 0; id < L.view.size(); ++id)
    {
        const mba::index<D> t = L.view.coord(L.view.keyOf(id));
        for (int j = 0; j < per; ++j)
            if (L.coefficientNodes[id*per + j]) nodes[tileNodeKey<D>(t, j)] = L.coefficientNodes[id*per + j];
    }
    return nodes;
}

/// The nodes of tile t, omega value j, in masks (0 where none)
template <int D>
std::uint64_t nodesAt(const tileNodeMasks<D>& masks, const mba::index<D>& t, int j)
{
    const auto it = masks.find(tileNodeKey<D>(t, j));
    return it == masks.end() ? 0 : it->second;
}

/// A read test for planLevel that keeps what it is given (a level's
/// coefficient tiles alone: view, level, scale, coefficientNodes) in c and
/// answers read, so that the plan goes on
template <int D>
std::function<bool(const mba::levelPlan<D>&)> coefficientTilesOf(mba::levelPlan<D>& c)
{
    return [&c](const mba::levelPlan<D>& L) {
        c.level = L.level;
        c.scale = L.scale;
        c.view = L.view;
        c.coefficientNodes = L.coefficientNodes;
        return true;
    };
}

template <int D>
std::vector<mba::point<D>> randomPoints(std::size_t n, unsigned seed, double lo = 0, double hi = 1)
{
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> U(lo, hi);
    std::vector<mba::point<D>> p(n);
    for (auto& x : p) for (auto& c : x) c = U(rng);
    return p;
}

/// k points per edge of every face of the unit cube (D=3) / square (D=2)
template <int D>
std::vector<mba::point<D>> surfacePoints(int k)
{
    std::vector<mba::point<D>> p;
    for (int d = 0; d < D; ++d)
        for (int side = 0; side < 2; ++side)
            for (long i = 0; i < (D == 3 ? long(k)*k : k); ++i)
            {
                mba::point<D> x;
                x[d] = side;
                x[(d + 1) % D] = double(i % k)/(k - 1);
                if (D == 3) x[(d + 2) % D] = double(i / k)/(k - 1);
                p.push_back(x);
            }
    return p;
}

/// Smooth vector field, component c
template <int D>
double smooth(const mba::point<D>& x, int c)
{
    double s = std::sin(2.1*x[0] + c)*std::cos(1.3*x[1] - 0.5*c);
    if (D == 3) s += 0.5*std::sin(1.7*x[2] + 0.3*c);
    return s;
}

template <int D>
std::vector<double> smoothValues(const std::vector<mba::point<D>>& p, int nc)
{
    std::vector<double> v(p.size()*nc);
    for (std::size_t i = 0; i < p.size(); ++i)
        for (int c = 0; c < nc; ++c) v[i*nc + c] = smooth<D>(p[i], c);
    return v;
}

inline double maxAbs(const std::vector<double>& v)
{
    double m = 0;
    for (double x : v) m = std::max(m, std::abs(x));
    return m;
}

/// A k^(D-1) grid on each of the two faces x_(D-1) = 0 and 1 of the unit
/// cube (square), each point moved by up to jitter of the spacing (seeded):
/// a mesh's top and bottom, whose finest levels are separated
template <int D>
std::vector<mba::point<D>> twoFaces(int k, double jitter, unsigned seed)
{
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> U(-jitter/(k - 1), jitter/(k - 1));
    std::vector<mba::point<D>> p;
    for (int side = 0; side < 2; ++side)
        for (long i = 0; i < (D == 3 ? long(k)*k : k); ++i)
        {
            mba::point<D> x;
            x[0] = double(i % k)/(k - 1) + U(rng);
            if (D == 3) x[1] = double(i / k)/(k - 1) + U(rng);
            x[D - 1] = side;
            p.push_back(x);
        }
    return p;
}

/// Every step-th of points on the faces x_(D-1) = 0 and 1, moved d inside:
/// evaluation points whose stencils read the faces' finest levels
template <int D>
std::vector<mba::point<D>> insideFaces(const std::vector<mba::point<D>>& c, std::size_t step, double d)
{
    std::vector<mba::point<D>> p;
    for (std::size_t i = 0; i < c.size(); i += step)
    {
        mba::point<D> x = c[i];
        x[D - 1] = x[D - 1] > 0.5 ? x[D - 1] - d : x[D - 1] + d;
        p.push_back(x);
    }
    return p;
}

/// A wall that slides and one that is fixed, as a mesh gives them: the
/// grids of twoFaces (jitter 0.3), the face x_(D-1) = 0 constraining only
/// its normal component (D - 1: to 0), the face x_(D-1) = 1 all (smooth
/// values); evaluated: the sliding face's points, which read all but the
/// normal component (evaluationMask), and points 0.25 inside either face
template <int D>
struct slidingWall
{
    std::vector<mba::point<D>> c, e;
    std::vector<std::uint8_t> mask, evaluationMask;
    std::vector<double> v;

    explicit slidingWall(int k)
    {
        c = twoFaces<D>(k, 0.3, 81);
        for (const mba::point<D>& x : c)
            for (int q = 0; q < D; ++q)
            {
                const bool slides = x[D - 1] < 0.5;
                mask.push_back(!slides || q == D - 1);
                v.push_back(slides ? 0.0 : smooth<D>(x, q));
            }
        for (const mba::point<D>& x : c)
        {
            if (x[D - 1] > 0.5) continue;
            e.push_back(x);
            for (int q = 0; q < D; ++q) evaluationMask.push_back(q != D - 1);
        }
        for (const mba::point<D>& x : insideFaces<D>(c, 3, 0.25))
        {
            e.push_back(x);
            evaluationMask.insert(evaluationMask.end(), D, 1);
        }
    }
};

/// A mask (point x component) in which every other of n points leaves one
/// of its nc components free, in turn: components with mixed masks
inline std::vector<std::uint8_t> mixedMask(std::size_t n, int nc)
{
    std::vector<std::uint8_t> mask(n*nc, 1);
    for (std::size_t i = 0; i < n; i += 2) mask[i*nc + i % nc] = 0;
    return mask;
}

/// The method written out plainly, as an oracle: the paper's Eq. 5-6 level
/// after level, each level's lattice a std::map of the nodes the control
/// points' stencils touch, omega per component over the points that
/// constrain it (mask, point x component; empty: all). Returns the sum of
/// the first `levels` levels at the points e (no affine start).
template <int D>
std::vector<double> plainMBA(const mba::domain<D>& dom, int levels, int nc, const std::vector<mba::point<D>>& c,
                             std::vector<double> r, const std::vector<std::uint8_t>& mask,
                             const std::vector<mba::point<D>>& e)
{
    using node = std::array<std::int64_t, D>;
    auto forNodes = [&](const mba::point<D>& x, int k, auto&& f) {
        mba::point<D> u = dom.local0(x.data());
        for (double& t : u) t *= std::ldexp(1.0, k);
        const mba::stencil<D> st(u.data());
        for (int a = 0; a < (1 << 2*D); ++a)
        {
            node n;
            double w = 1;
            for (int d = 0; d < D; ++d) { const int o = (a >> 2*d) & 3; n[d] = st.base[d] + o; w *= st.w[d][o]; }
            f(n, w, st.sumSquares());
        }
    };
    auto on = [&](std::size_t i, int q) { return mask.empty() || mask[i*nc + q]; };
    std::vector<double> out(e.size()*nc, 0.0), fc(c.size()*nc);
    for (int k = 0; k < levels; ++k)
    {
        std::map<node, std::vector<double>> lattice;   // delta, then omega, per component
        for (std::size_t i = 0; i < c.size(); ++i)
            forNodes(c[i], k, [&](const node& n, double w, double S) {
                std::vector<double>& dw = lattice[n];
                dw.resize(2*nc, 0.0);
                for (int q = 0; q < nc; ++q)
                    if (on(i, q)) { dw[q] += w*w*(w*r[i*nc + q]/S); dw[nc + q] += w*w; }
            });
        auto add = [&](const mba::point<D>& x, double* acc) {
            forNodes(x, k, [&](const node& n, double w, double) {
                const auto it = lattice.find(n);
                if (it == lattice.end()) return;
                for (int q = 0; q < nc; ++q)
                    if (it->second[nc + q] > 0) acc[q] += w*it->second[q]/it->second[nc + q];
            });
        };
        std::fill(fc.begin(), fc.end(), 0.0);
        for (std::size_t i = 0; i < c.size(); ++i) add(c[i], &fc[i*nc]);
        for (std::size_t i = 0; i < r.size(); ++i) r[i] -= fc[i];
        for (std::size_t j = 0; j < e.size(); ++j) add(e[j], &out[j*nc]);
    }
    return out;
}

} // namespace bsmTest
#endif
