#include "pointSets.hpp"
#include "spatialOrder.hpp"

namespace mba {

template <int D>
controlPoints<D>::controlPoints(pointsView<D> points, int nc, std::vector<std::uint8_t> pointMask)
:
    x(points), nComponents(nc), mask(std::move(pointMask))
{}

template <int D>
void controlPoints<D>::classify(const communicator& comm)
{
    // Which points constrain anything; whether masks differ between components
    active.assign(x.size, 1);
    bool mixed = false;
    if (!mask.empty())
    {
        for (std::size_t i = 0; i < x.size; ++i)
        {
            int on = 0;
            for (int c = 0; c < nComponents; ++c) on += mask[i*nComponents + c] != 0;
            active[i] = on > 0;
            mixed = mixed || (on > 0 && on < nComponents);
        }
    }
    omegaPerNode = comm.max(mixed ? 1.0 : 0.0) > 0 ? nComponents : 1;
    std::int64_t nActive = 0;
    for (auto a : active) nActive += a;
    nActiveGlobal = comm.sum(nActive);
}

template <int D>
void controlPoints<D>::arrange(const domain<D>& dom)
{
    order = spatialOrder<D>(x, dom, &active);
    for (const std::uint32_t i : order) u0.push_back(dom.local0(x[i]));
}

template <int D>
std::int64_t controlPoints<D>::bytes() const
{
    return std::int64_t(active.capacity() + mask.capacity() + order.capacity()*sizeof(std::uint32_t)
        + u0.capacity()*sizeof(point<D>));
}

template <int D>
void evaluationPoints<D>::arrange(const domain<D>& dom)
{
    order = spatialOrder<D>(x, dom, nullptr);
    if (ownOrderIsAsShort<D>(x, order)) order = std::vector<std::uint32_t>();
    else
    {
        position.resize(x.size);
        for (std::size_t q = 0; q < x.size; ++q) position[order[q]] = std::uint32_t(q);
    }
    lo0.fill(HUGE_VAL);
    hi0.fill(-HUGE_VAL);
    u0.reserve(x.size);
    for (std::size_t q = 0; q < x.size; ++q)
    {
        const point<D> u = dom.local0(x[at(q)]);
        u0.push_back(u);
        for (int d = 0; d < D; ++d) { lo0[d] = std::min(lo0[d], u[d]); hi0[d] = std::max(hi0[d], u[d]); }
    }
}

template <int D>
std::int64_t evaluationPoints<D>::bytes() const
{
    return std::int64_t(mask.capacity() + (order.capacity() + position.capacity())*sizeof(std::uint32_t)
        + u0.capacity()*sizeof(point<D>));
}

template struct controlPoints<2>;
template struct controlPoints<3>;
template struct evaluationPoints<2>;
template struct evaluationPoints<3>;

} // namespace mba
