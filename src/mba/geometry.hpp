// bsplineMorph: OpenFOAM-free multilevel B-spline core
// Points, index boxes and the lattice domain.
#ifndef MBA_GEOMETRY_HPP
#define MBA_GEOMETRY_HPP

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace mba {

template <int D> using point = std::array<double, D>;
template <int D> using index = std::array<std::int64_t, D>;

/// Throws std::invalid_argument with the message unless the condition holds
inline void precondition(bool ok, const std::string& msg)
{
    if (!ok) throw std::invalid_argument(msg);
}

/// A read-only view of n points stored as D consecutive doubles each (e.g. an
/// OpenFOAM pointField). The data are not copied: they must outlive the view's users.
template <int D> struct pointsView
{
    const double* data = nullptr;
    std::size_t size = 0;

    pointsView() = default;
    pointsView(const double* d, std::size_t n) : data(d), size(n) {}
    pointsView(const std::vector<point<D>>& p) : data(p.empty() ? nullptr : p[0].data()), size(p.size()) {}
    /// A view of a temporary would dangle: not allowed
    pointsView(const std::vector<point<D>>&&) = delete;

    const double* operator[](std::size_t i) const { return data + D*i; }
};

/// Inclusive box in index space
template <int D> struct indexBox
{
    index<D> lo, hi;

    bool contains(const index<D>& i) const
    {
        for (int d = 0; d < D; ++d)
            if (i[d] < lo[d] || hi[d] < i[d]) return false;
        return true;
    }

    bool intersects(const indexBox& b) const
    {
        for (int d = 0; d < D; ++d)
            if (b.hi[d] < lo[d] || hi[d] < b.lo[d]) return false;
        return true;
    }
};

/// Calls f(i) for every index of the box, the last direction fastest
template <int D, class F>
void forEachIndex(const indexBox<D>& b, F&& f)
{
    index<D> i = b.lo;
    for (;;)
    {
        f(static_cast<const index<D>&>(i));
        int d = D - 1;
        while (d >= 0 && i[d] == b.hi[d]) { i[d] = b.lo[d]; --d; }
        if (d < 0) break;
        ++i[d];
    }
}

/// Position of index i among the box's indices in the order of forEachIndex
/// (the last direction fastest)
template <int D>
inline std::int64_t boxIndex(const indexBox<D>& b, const index<D>& i)
{
    std::int64_t g = 0;
    for (int d = 0; d < D; ++d) g = g*(b.hi[d] - b.lo[d] + 1) + (i[d] - b.lo[d]);
    return g;
}

/// Bounding box in space
template <int D> struct box
{
    point<D> lo, hi;

    static box empty()
    {
        box b;
        b.lo.fill(HUGE_VAL);
        b.hi.fill(-HUGE_VAL);
        return b;
    }
    bool isEmpty() const { return lo[0] > hi[0]; }
    void add(const double* x)
    {
        for (int d = 0; d < D; ++d)
        {
            if (x[d] < lo[d]) lo[d] = x[d];
            if (x[d] > hi[d]) hi[d] = x[d];
        }
    }
    void add(const box& b)
    {
        if (!b.isEmpty()) { add(b.lo.data()); add(b.hi.data()); }
    }
};

/// The lattice domain: level k has cubic cells of edge h0/2^k; a point's local
/// coordinate at level k is u = (x - lo)/h_k = u0*2^k (exact scaling), its cell
/// floor(u) and its 4^D stencil nodes floor(u) + 0..3 (node 0 lies at lo - h_k).
template <int D> struct domain
{
    point<D> lo{};                 ///< lower corner (padded)
    double h0 = 1;                 ///< level-0 cell edge
    std::array<std::int64_t, D> n0{}; ///< level-0 cells per direction

    /// Pad the box by padding*largest extent on each side; cubic cells with
    /// initialGrid cells along the longest edge.
    static domain fromBox(const box<D>& b, int initialGrid, double padding)
    {
        precondition(initialGrid >= 1, "mba: initialGrid must be >= 1, got " + std::to_string(initialGrid));
        precondition(padding > 0 && std::isfinite(padding), "mba: padding must be > 0");
        box<D> bb = b;
        if (bb.isEmpty()) { bb.lo.fill(0.0); bb.hi.fill(1.0); }
        double ext = 0, mag = 0;
        for (int d = 0; d < D; ++d)
        {
            ext = std::max(ext, bb.hi[d] - bb.lo[d]);
            mag = std::max({mag, std::abs(bb.hi[d]), std::abs(bb.lo[d])});
        }
        // A single point (no extent at all): a box of the point's magnitude
        if (!(ext > 1e-12*mag) ) ext = std::max(mag, 1.0);
        const double pad = padding*ext;
        domain dom;
        dom.h0 = (ext + 2*pad)/initialGrid;
        for (int d = 0; d < D; ++d)
        {
            const double e = bb.hi[d] - bb.lo[d] + 2*pad;
            dom.n0[d] = std::max<std::int64_t>(1, std::int64_t(std::ceil(e/dom.h0 - 1e-9)));
            // centre the padded extent in the cells
            dom.lo[d] = bb.lo[d] - pad - 0.5*(dom.n0[d]*dom.h0 - e);
        }
        return dom;
    }

    /// Level-0 local coordinates of x; throws std::out_of_range outside the domain
    point<D> local0(const double* x) const
    {
        point<D> u;
        for (int d = 0; d < D; ++d)
        {
            u[d] = (x[d] - lo[d])/h0;
            if (!(u[d] >= 0.0 && u[d] < double(n0[d])))
            {
                std::string s = "mba: point (";
                for (int e = 0; e < D; ++e) s += (e ? ", " : "") + std::to_string(x[e]);
                throw std::out_of_range(s + ") is outside the lattice domain");
            }
        }
        return u;
    }

    /// Level-0 local coordinates of x, or false when x is outside the domain
    bool tryLocal0(const double* x, point<D>& u) const
    {
        for (int d = 0; d < D; ++d)
        {
            u[d] = (x[d] - lo[d])/h0;
            if (!(u[d] >= 0.0 && u[d] < double(n0[d]))) return false;
        }
        return true;
    }

    /// Nodes per direction at level k
    std::int64_t nodes(int k, int d) const { return (n0[d] << k) + 3; }
};

} // namespace mba
#endif
