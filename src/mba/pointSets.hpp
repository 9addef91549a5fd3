// bsplineMorph: OpenFOAM-free multilevel B-spline core (internal header)
// This rank's control and evaluation points as the levels see them: the
// control points' masks, both sets in spatial order (spatialOrder.hpp) with
// their level-0 local coordinates, which every level scales to its own.
#ifndef MBA_POINTSETS_HPP
#define MBA_POINTSETS_HPP

#include "communicator.hpp"
#include "hugePages.hpp"
#include "lattice.hpp"

#include <cstdint>
#include <utility>
#include <vector>

namespace mba {

/// This rank's control points
template <int D>
struct controlPoints
{
    pointsView<D> x;                        ///< coordinates (the caller's: not copied)
    int nComponents = 1;                    ///< values a point
    /// omega values a lattice node holds: 1, or nComponents when the masks
    /// differ between components somewhere (each component its own omega)
    int omegaPerNode = 1;
    std::vector<std::uint8_t> mask;         ///< point x component 0/1; empty: every component constrained
    std::vector<std::uint8_t> active;       ///< per point: it constrains some component
    std::int64_t nActiveGlobal = 0;         ///< active points of all ranks
    std::vector<std::uint32_t> order;       ///< the active points in spatial order
    std::vector<point<D>> u0;               ///< their level-0 local coordinates, in that order

    /// The points x (nc values each) and their mask, not yet classified
    controlPoints(pointsView<D> points, int nc, std::vector<std::uint8_t> pointMask);

    /// Sets active, omegaPerNode and nActiveGlobal. Collective.
    void classify(const communicator& comm);

    /// Sets order and u0 (the domain contains the active points)
    void arrange(const domain<D>& dom);

    /// Whether point i constrains component c
    bool constrains(std::size_t i, int c) const { return mask.empty() || mask[i*nComponents + c] != 0; }

    /// The components point i constrains, in on[0..nComponents): on, or
    /// nullptr when every active point constrains all (one omega per node)
    const bool* constrained(std::size_t i, bool* on) const
    {
        if (omegaPerNode == 1) return nullptr;
        for (int c = 0; c < nComponents; ++c) on[c] = mask[i*nComponents + c] != 0;
        return on;
    }

    /// The stencil of the q-th point in order at the level of scale s
    inline __attribute__((always_inline)) stencil<D> stencilAt(std::size_t q, double s) const
    {
        return levelStencil<D>(u0[q], s);
    }

    /// f(i, stencil) for the active points i in order, their stencils at the
    /// level of scale s
    template <class F>
    void forEachStencil(double s, F&& f) const
    {
        for (std::size_t q = 0; q < order.size(); ++q) f(std::size_t(order[q]), stencilAt(q, s));
    }

    /// Bytes of the masks, the order and the coordinates
    std::int64_t bytes() const;
};

/// This rank's evaluation points, in the order evaluation sweeps them
template <int D>
struct evaluationPoints
{
    pointsView<D> x;                        ///< coordinates (the caller's: not copied)
    int nComponents = 1;                    ///< values a point
    std::vector<std::uint8_t> mask;         ///< point x component 0/1: the caller reads it; empty: all
    /// The sweep's order: spatial, or empty: the points' own order (when that
    /// is about as short a path through them: the results are then written in
    /// sequence)
    std::vector<std::uint32_t> order;
    std::vector<std::uint32_t> position;    ///< position of each point in order (spatial order only)
    hugeVector<point<D>> u0;                ///< level-0 local coordinates, in the sweep's order
    point<D> lo0, hi0;                      ///< level-0 local box of the points

    evaluationPoints(pointsView<D> points, int nc, std::vector<std::uint8_t> readMask)
    :
        x(points), nComponents(nc), mask(std::move(readMask))
    {}

    /// Whether the caller reads component c of point i
    bool reads(std::size_t i, int c) const { return mask.empty() || mask[i*nComponents + c] != 0; }

    /// Sets order, position, u0 and their box (the domain contains the points)
    void arrange(const domain<D>& dom);

    std::size_t size() const { return x.size; }

    /// The point at position q of the sweep's order
    std::size_t at(std::size_t q) const { return order.empty() ? q : order[q]; }

    /// Bytes of the mask, the order and the coordinates
    std::int64_t bytes() const;
};

} // namespace mba
#endif
