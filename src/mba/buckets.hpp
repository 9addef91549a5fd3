// bsplineMorph: OpenFOAM-free multilevel B-spline core
// Clustering by recursive bisection: items with D coordinates are split at the
// median of their widest direction until a group holds at most leafSize items.
// Used for the buckets of a rank's lattice tiles (index space) and for the
// clusters of its query points (space): each group is summarised by a box.
#ifndef MBA_BUCKETS_HPP
#define MBA_BUCKETS_HPP

#include "geometry.hpp"

#include <algorithm>
#include <numeric>

namespace mba {

/// Groups of item indices; coord(i) gives item i's coordinates (array of D)
template <int D, class Coord>
std::vector<std::vector<std::int64_t>> bisect(std::int64_t n, Coord coord, std::int64_t leafSize)
{
    std::vector<std::vector<std::int64_t>> groups;
    if (n == 0) return groups;
    std::vector<std::int64_t> idx(n);
    std::iota(idx.begin(), idx.end(), 0);
    // explicit stack of [begin, end) ranges
    std::vector<std::pair<std::int64_t, std::int64_t>> todo{{0, n}};
    while (!todo.empty())
    {
        const auto r = todo.back();
        todo.pop_back();
        const std::int64_t len = r.second - r.first;
        auto lo = coord(idx[r.first]), hi = lo;
        for (std::int64_t i = r.first; i < r.second; ++i)
        {
            const auto c = coord(idx[i]);
            for (int d = 0; d < D; ++d)
            {
                lo[d] = std::min(lo[d], c[d]);
                hi[d] = std::max(hi[d], c[d]);
            }
        }
        int dir = 0;
        for (int d = 1; d < D; ++d)
            if (hi[d] - lo[d] > hi[dir] - lo[dir]) dir = d;
        if (len <= leafSize || hi[dir] == lo[dir])
        {
            groups.emplace_back(idx.begin() + r.first, idx.begin() + r.second);
            continue;
        }
        const std::int64_t mid = r.first + len/2;
        std::nth_element(idx.begin() + r.first, idx.begin() + mid, idx.begin() + r.second,
            [&](std::int64_t a, std::int64_t b) { return coord(a)[dir] < coord(b)[dir]; });
        todo.push_back({mid, r.second});
        todo.push_back({r.first, mid});
    }
    return groups;
}

} // namespace mba
#endif
