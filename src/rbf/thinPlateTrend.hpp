// bsplineMorph: OpenFOAM-free radial basis function interpolation
// A smooth trend for the multilevel B-splines (mba::multilevel::fit with a
// trend): a thin-plate spline with its linear polynomial through a subset of
// the control points, sampled at points the caller gives once (a coarse
// level's nodes), whose basis it keeps: a sample is then one solve and one
// product per point and value. Beyond the last control points the multilevel field falls back
// towards the smooth interpolation of all the data; the spline continues the
// data's gradient there instead (the field a deforming wall's rigid layers
// need beyond their zone: docs/QUALITY.md).
//
// The subset, per component: of the control points that constrain it, per
// cell of a grid of cubic cells over a box and per class of point (the
// caller's classes: a wall's points and the points of a zone moved with it,
// say, which lie close together but move differently), the point nearest the
// cell's centre, the least (distance, coordinates) over all ranks: the subset
// does not depend on the decomposition, and the gathered subset is small
// (at most the grid's cells times the classes, never the whole boundary).
// Components with the same subset share one system (rbf::interpolant:
// factored once, one solve per set of values).
#ifndef RBF_THINPLATETREND_HPP
#define RBF_THINPLATETREND_HPP

#include "rbfInterpolant.hpp"

#include <memory>

namespace rbf {

template <int D>
class thinPlateTrend
{
    /// Components that share a subset, the subset's local control points
    /// and its system
    struct group
    {
        std::vector<int> components;
        std::vector<std::size_t> points;        ///< indices of this rank's control points
        std::vector<point<D>> x;                ///< their coordinates (the system's view)
        std::unique_ptr<interpolant<D>> spline;
        std::vector<double> basis;              ///< the spline's basis at the sample points
    };

    int nc_;
    std::size_t nSamples_;
    std::vector<group> groups_;
    long centres_ = 0;

public:
    /// Collective. control, mask (point x component, empty: all constrained):
    /// this rank's control points; classes: per control point its class
    /// (empty: one class); bounds: a box holding every rank's control
    /// points; grid: cells along its longest edge (>= 1); samples: where
    /// sample() gives the spline
    thinPlateTrend(const mba::communicator& comm, int nComponents, pointsView<D> control,
                   const std::vector<std::uint8_t>& mask, const std::vector<std::uint8_t>& classes,
                   const mba::box<D>& bounds, int grid, pointsView<D> samples);

    /// Collective: the spline through the subset's values (values: this
    /// rank's control values, point x component) at the sample points
    /// (point x component; the same on every rank given the same points)
    void sample(const std::vector<double>& values, std::vector<double>& out);

    /// The subset's points (all ranks, summed over the systems)
    long centres() const { return centres_; }
    /// The systems (components with the same subset share one)
    int systems() const { return int(groups_.size()); }
};

} // namespace rbf
#endif
