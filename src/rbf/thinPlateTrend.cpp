#include "thinPlateTrend.hpp"
#include "collectively.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace rbf {

template <int D>
thinPlateTrend<D>::thinPlateTrend(const mba::communicator& comm, int nComponents, pointsView<D> control,
                                  const std::vector<std::uint8_t>& mask, const std::vector<std::uint8_t>& classes,
                                  const mba::box<D>& bounds, int grid, pointsView<D> samples)
:
    nc_(nComponents), nSamples_(samples.size)
{
    mba::collectively(comm, [&] {
        mba::precondition(grid >= 1 && grid <= 32, "rbf: the trend's grid must be in [1, 32], got "
            + std::to_string(grid));
        mba::precondition(nc_ >= 1 && nc_ <= 3, "rbf: 1 to 3 value components, got " + std::to_string(nc_));
        mba::precondition(mask.empty() || mask.size() == control.size*nc_, "rbf: the mask has "
            + std::to_string(mask.size()) + " entries, expected " + std::to_string(control.size*nc_));
        mba::precondition(classes.empty() || classes.size() == control.size, "rbf: "
            + std::to_string(classes.size()) + " classes, expected " + std::to_string(control.size));
    });
    int nClasses = 1;
    for (const std::uint8_t k : classes) nClasses = std::max(nClasses, int(k) + 1);
    nClasses = int(comm.max(double(nClasses)));

    // The grid: cubic cells, grid of them along the box's longest edge
    double ext = 0;
    for (int d = 0; d < D; ++d) ext = std::max(ext, bounds.hi[d] - bounds.lo[d]);
    const double edge = ext > 0 ? ext/grid : 1.0;
    std::array<long, D> n;
    long nCells = 1;
    for (int d = 0; d < D; ++d)
    {
        n[d] = std::max(1L, long(std::ceil((bounds.hi[d] - bounds.lo[d])/edge - 1e-9)));
        nCells *= n[d];
    }

    // Per component, class and cell (a slot): this rank's least (squared
    // distance to the cell's centre, coordinates), then all ranks'
    constexpr int K = D + 1;
    typedef std::array<double, K> key;
    const long nSlots = long(nc_)*nClasses*nCells;
    std::vector<double> best(nSlots*K, std::numeric_limits<double>::infinity());
    std::vector<key> pointKey(control.size);
    std::vector<long> pointCell(control.size);
    // (control point i's slot for component c, once its cell is known)
    auto slotOf = [&](std::size_t i, int c) {
        const long cls = classes.empty() ? 0 : classes[i];
        return &best[((long(c)*nClasses + cls)*nCells + pointCell[i])*K];
    };
    for (std::size_t i = 0; i < control.size; ++i)
    {
        long cell = 0;
        double d2 = 0;
        for (int d = 0; d < D; ++d)
        {
            const long j = std::min(n[d] - 1, std::max(0L, long(std::floor((control[i][d] - bounds.lo[d])/edge))));
            cell = cell*n[d] + j;
            const double r = control[i][d] - (bounds.lo[d] + (double(j) + 0.5)*edge);
            d2 += r*r;
        }
        key& k = pointKey[i];
        k[0] = d2;
        for (int d = 0; d < D; ++d) k[1 + d] = control[i][d];
        pointCell[i] = cell;
        for (int c = 0; c < nc_; ++c)
        {
            if (!mask.empty() && !mask[i*nc_ + c]) continue;
            double* b = slotOf(i, c);
            if (std::lexicographical_compare(k.begin(), k.end(), b, b + K)) std::copy(k.begin(), k.end(), b);
        }
    }
    const std::vector<double> all = comm.allGatherFixed(best);
    for (std::size_t at = 0; at < all.size(); at += best.size())
        for (long s = 0; s < nSlots; ++s)
        {
            const double* a = &all[at + s*K];
            double* b = &best[s*K];
            if (std::lexicographical_compare(a, a + K, b, b + K)) std::copy(a, a + K, b);
        }

    // Components whose slots hold the same points share a group; the bases
    // kept: the samples times the centres and terms (at most 2^25 doubles)
    const long perComponent = long(nClasses)*nCells*K;
    double basisValues = 0;
    for (int c = 0; c < nc_; ++c)
    {
        const double* mine = &best[c*perComponent];
        long used = 0;
        for (long s = 0; s < nClasses*nCells; ++s) used += std::isfinite(mine[s*K]);
        if (used == 0) continue;    // (no point constrains it: the trend is zero there)
        group* g = nullptr;
        for (group& h : groups_)
            if (std::equal(mine, mine + perComponent, &best[h.components[0]*perComponent])) g = &h;
        if (g)
        {
            g->components.push_back(c);
            continue;
        }
        groups_.emplace_back();
        g = &groups_.back();
        g->components.push_back(c);
        centres_ += used;
        basisValues += double(samples.size)*double(used + D + 1);
        for (std::size_t i = 0; i < control.size; ++i)
        {
            if (!mask.empty() && !mask[i*nc_ + c]) continue;
            if (std::equal(pointKey[i].begin(), pointKey[i].end(), slotOf(i, c)))
            {
                g->points.push_back(i);
                point<D> x;
                for (int d = 0; d < D; ++d) x[d] = control[i][d];
                g->x.push_back(x);
            }
        }
    }
    mba::collectively(comm, [&] {
        mba::precondition(basisValues <= double(1L << 25), "rbf: the thin-plate trend's basis at its "
            + std::to_string(samples.size) + " sample points would take "
            + std::to_string(long(basisValues*sizeof(double)/1048576)) + " MB (at most 256): sample it at fewer"
            " points (a coarser level) or through fewer centres (a coarser grid)");
    });
    params p;
    p.function = kernel::thinPlateSpline;
    p.polynomial = true;
    for (group& g : groups_)
    {
        try
        {
            g.spline.reset(new interpolant<D>(comm, p, int(g.components.size()), g.x));
            g.basis = g.spline->basisAt(samples);
        }
        catch (const mba::collectiveError& e)
        {
            // (thrown on every rank alike)
            std::string which;
            for (const int c : g.components) which += (which.empty() ? "" : ", ") + std::to_string(c);
            throw mba::collectiveError(std::string(e.what()) + ": the thin-plate trend's centres for component "
                + which + " (the control points that constrain it, nearest the grid's cells' centres) may all"
                " lie in one plane or on one line, which no thin-plate spline with its linear polynomial fits");
        }
    }
}

template <int D>
void thinPlateTrend<D>::sample(const std::vector<double>& values, std::vector<double>& out)
{
    out.assign(nSamples_*nc_, 0.0);
    std::vector<double> v, s;
    for (const group& g : groups_)
    {
        const std::size_t m = g.components.size();
        v.clear();
        for (const std::size_t i : g.points)
            for (const int c : g.components) v.push_back(values[i*nc_ + c]);
        g.spline->fit(v);
        g.spline->evaluate(g.basis, s);
        for (std::size_t q = 0; q < nSamples_; ++q)
            for (std::size_t j = 0; j < m; ++j) out[q*nc_ + g.components[j]] = s[q*m + j];
    }
}

template class thinPlateTrend<2>;
template class thinPlateTrend<3>;

} // namespace rbf
