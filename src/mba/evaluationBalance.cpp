// bsplineMorph: OpenFOAM-free multilevel B-spline core
// Evaluation points handed from busy ranks to idle ones (evaluationBalance.hpp).
#include "evaluationBalance.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace mba {

namespace {

template <int D>
double centreDistance(const box<D>& a, const box<D>& b)
{
    if (a.isEmpty() || b.isEmpty()) return HUGE_VAL;
    double s = 0;
    for (int d = 0; d < D; ++d)
    {
        const double c = 0.5*(a.lo[d] + a.hi[d]) - 0.5*(b.lo[d] + b.hi[d]);
        s += c*c;
    }
    return s;
}

/// Squared distance from x to the box (0 inside)
template <int D>
double boxDistance(const double* x, const box<D>& b)
{
    double s = 0;
    for (int d = 0; d < D; ++d)
    {
        const double c = x[d] < b.lo[d] ? b.lo[d] - x[d] : x[d] > b.hi[d] ? x[d] - b.hi[d] : 0.0;
        s += c*c;
    }
    return s;
}

} // namespace


template <int D>
std::vector<evaluationMove> balanceMoves(const std::vector<rankWork<D>>& ranks, double threshold)
{
    const int P = int(ranks.size());
    std::vector<evaluationMove> moves;
    double total = 0, most = 0;
    for (const rankWork<D>& r : ranks) { total += r.work; most = std::max(most, r.work); }
    const double mean = total/std::max(P, 1);
    if (P < 2 || !(mean > 0) || most <= threshold*mean) return moves;

    std::vector<double> surplus(P, 0), deficit(P, 0);
    std::vector<std::int64_t> left(P, 0);
    std::vector<int> givers;
    for (int r = 0; r < P; ++r)
    {
        const rankWork<D>& w = ranks[r];
        if (w.work > mean && w.points > 0)
        {
            surplus[r] = w.work - mean;
            left[r] = w.points;
            givers.push_back(r);
        }
        else if (w.work < mean) deficit[r] = mean - w.work;
    }
    std::stable_sort(givers.begin(), givers.end(), [&](int a, int b) { return surplus[a] > surplus[b]; });
    for (const int g : givers)
    {
        while (surplus[g] > 0 && left[g] > 0)
        {
            int q = -1;
            double best = HUGE_VAL;
            for (int r = 0; r < P; ++r)
            {
                if (!(deficit[r] > 0)) continue;
                const double d = centreDistance(ranks[g].bounds, ranks[r].bounds);
                if (q < 0 || d < best) { q = r; best = d; }
            }
            if (q < 0) break;
            const std::int64_t k = std::min(left[g], std::int64_t(std::floor(std::min(surplus[g], deficit[q]) + 0.5)));
            if (k <= 0) break;
            moves.push_back(evaluationMove{g, q, k});
            left[g] -= k;
            surplus[g] -= double(k);
            deficit[q] -= double(k);
            // (within half a point of the mean is at the mean)
            if (deficit[q] < 0.5) deficit[q] = 0;
            if (surplus[g] < 0.5) surplus[g] = 0;
        }
    }
    return moves;
}


template <int D>
evaluationBalance<D>::evaluationBalance(const communicator& comm, pointsView<D> points, double work,
                                        double threshold)
:
    comm_(comm),
    nOwn_(points.size)
{
    precondition(threshold >= 1, "evaluationBalance: the threshold must be at least 1");
    const int P = comm.size(), me = comm.rank();
    rankWork<D> mine;
    mine.work = work;
    mine.points = std::int64_t(points.size);
    for (std::size_t i = 0; i < points.size; ++i) mine.bounds.add(points[i]);
    const std::vector<std::vector<rankWork<D>>> all = comm.allGather(std::vector<rankWork<D>>{mine});
    std::vector<rankWork<D>> ranks(P);
    double total = 0, most = 0;
    for (int r = 0; r < P; ++r)
    {
        ranks[r] = all[r].at(0);
        total += ranks[r].work;
        most = std::max(most, ranks[r].work);
    }
    if (total > 0) imbalance_ = most*P/total;
    moves_ = balanceMoves(ranks, threshold);

    // The own points each move takes: those nearest the receiver's box
    // (ties: the lower index), from the points not taken yet
    sent_.assign(P, {});
    std::vector<char> taken(nOwn_, 0);
    for (const evaluationMove& m : moves_)
    {
        if (m.from != me) continue;
        std::vector<std::size_t> candidates;
        for (std::size_t i = 0; i < nOwn_; ++i) if (!taken[i]) candidates.push_back(i);
        std::vector<double> dist(nOwn_, 0);
        for (const std::size_t i : candidates) dist[i] = boxDistance(points[i], ranks[m.to].bounds);
        const std::size_t k = std::min<std::size_t>(candidates.size(), std::size_t(m.count));
        std::nth_element(candidates.begin(), candidates.begin() + std::ptrdiff_t(k), candidates.end(),
                         [&](std::size_t a, std::size_t b) { return dist[a] < dist[b] || (dist[a] == dist[b] && a < b); });
        candidates.resize(k);
        std::sort(candidates.begin(), candidates.end());
        for (const std::size_t i : candidates) taken[i] = 1;
        std::vector<std::size_t>& s = sent_[m.to];
        s.insert(s.end(), candidates.begin(), candidates.end());
        std::sort(s.begin(), s.end());
    }
    for (std::size_t i = 0; i < nOwn_; ++i) if (!taken[i]) kept_.push_back(i);

    // The coordinates of the moved points to their receivers (the plan's
    // only exchange of sizes)
    std::vector<std::vector<double>> send(P);
    for (int q = 0; q < P; ++q)
        for (const std::size_t i : sent_[q]) send[q].insert(send[q].end(), points[i], points[i] + D);
    const std::vector<std::vector<double>> got = comm.exchange(send);
    for (const std::size_t i : kept_) xyz_.insert(xyz_.end(), points[i], points[i] + D);
    receivedCount_.assign(P, 0);
    for (int r = 0; r < P; ++r)
    {
        if (r == me) continue;
        receivedCount_[r] = got[r].size()/D;
        xyz_.insert(xyz_.end(), got[r].begin(), got[r].end());
    }
}


template <int D>
void evaluationBalance<D>::restore(const std::vector<double>& evaluated, int nComponents,
                                   std::vector<double>& own) const
{
    const std::size_t nc = std::size_t(nComponents);
    precondition(evaluated.size() == points().size*nc,
                 "evaluationBalance::restore: the values must be those at points()");
    const int P = comm_.size();
    own.resize(nOwn_*nc);
    for (std::size_t k = 0; k < kept_.size(); ++k)
        std::copy_n(&evaluated[k*nc], nc, &own[kept_[k]*nc]);
    std::vector<std::vector<double>> send(P), recv(P);
    std::size_t offset = kept_.size()*nc;
    for (int r = 0; r < P; ++r)
    {
        const std::size_t n = receivedCount_[r]*nc;
        send[r].assign(evaluated.begin() + std::ptrdiff_t(offset), evaluated.begin() + std::ptrdiff_t(offset + n));
        offset += n;
        recv[r].resize(sent_[r].size()*nc);
    }
    comm_.exchange(send, recv);
    for (int r = 0; r < P; ++r)
        for (std::size_t k = 0; k < sent_[r].size(); ++k)
            std::copy_n(&recv[r][k*nc], nc, &own[sent_[r][k]*nc]);
}


template std::vector<evaluationMove> balanceMoves(const std::vector<rankWork<2>>&, double);
template std::vector<evaluationMove> balanceMoves(const std::vector<rankWork<3>>&, double);
template class evaluationBalance<2>;
template class evaluationBalance<3>;

} // namespace mba
