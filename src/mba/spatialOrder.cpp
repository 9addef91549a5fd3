#include "spatialOrder.hpp"

#include <algorithm>
#include <cmath>

namespace mba {

namespace {

/// Morton code of a point's level-0 local coordinates u on a 2^(63/D) grid
template <int D>
std::uint64_t morton(const point<D>& u, const domain<D>& dom)
{
    constexpr int bits = 63/D;
    std::uint64_t code = 0;
    std::uint64_t q[D];
    for (int d = 0; d < D; ++d)
    {
        const double f = u[d]/double(dom.n0[d]);
        q[d] = std::uint64_t(std::min(std::max(f, 0.0), 1.0 - 1e-16)*double(std::uint64_t(1) << bits));
    }
    for (int b = bits - 1; b >= 0; --b)
        for (int d = 0; d < D; ++d) code = (code << 1) | ((q[d] >> b) & 1u);
    return code;
}

} // namespace

template <int D>
std::vector<std::uint32_t> spatialOrder(pointsView<D> x, const domain<D>& dom, const std::vector<std::uint8_t>* select)
{
    std::vector<std::pair<std::uint64_t, std::uint32_t>> key;
    key.reserve(x.size);
    for (std::size_t i = 0; i < x.size; ++i)
        if (!select || (*select)[i]) key.emplace_back(morton<D>(dom.local0(x[i]), dom), std::uint32_t(i));
    std::sort(key.begin(), key.end());
    std::vector<std::uint32_t> order(key.size());
    for (std::size_t i = 0; i < key.size(); ++i) order[i] = key[i].second;
    return order;
}

template <int D>
bool ownOrderIsAsShort(pointsView<D> x, const std::vector<std::uint32_t>& order)
{
    auto path = [&](auto at) {
        double s = 0;
        for (std::size_t q = 1; q < x.size; ++q)
            for (int d = 0; d < D; ++d) s += std::abs(x[at(q)][d] - x[at(q - 1)][d]);
        return s;
    };
    return path([](std::size_t q) { return q; }) <= 1.5*path([&](std::size_t q) { return order[q]; });
}

template std::vector<std::uint32_t> spatialOrder<2>(pointsView<2>, const domain<2>&, const std::vector<std::uint8_t>*);
template std::vector<std::uint32_t> spatialOrder<3>(pointsView<3>, const domain<3>&, const std::vector<std::uint8_t>*);
template bool ownOrderIsAsShort<2>(pointsView<2>, const std::vector<std::uint32_t>&);
template bool ownOrderIsAsShort<3>(pointsView<3>, const std::vector<std::uint32_t>&);

} // namespace mba
